// Floating frame options: every choice satisfies Phi_CB Phi_rig0 = 1 (thesis 3.7, 3.23) about
// its own origin; each has its defining property.
#include "reducer/reduction/floating_frame.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "reducer/reduce_part.h"
#include "test_util.h"

namespace femb {
namespace {

const char* kSteel = "{E: 2.0e11, nu: 0.3, rho: 7870}";
const char* kRod = "{shape: circle, diameter: 0.006}";

Superelement ReduceWithFrame(const std::string& frame, const std::string& interfaces = "[{name: A}, {name: B}]") {
  return test::Reduce(test::StraightBeamYaml(0.3, 10, kRod, kSteel, interfaces, "reduction: {internal_modes: 4}\n"),
                      {"reduction.floating_frame=" + frame, "beam.theory=euler_bernoulli"});
}

double FrameIdentityError(const Superelement& se) {
  const Eigen::MatrixXd Phi_rig0 = RigidBodyModes(se, se.floating_frame.origin);
  return (se.floating_frame.Phi_CB * Phi_rig0 - Eigen::Matrix<double, 6, 6>::Identity()).cwiseAbs().maxCoeff();
}

TEST(FloatingFrame, EveryOptionIsConsistentWithRigidBodyModes) {
  for (const std::string frame : {"center_of_mass", "mean_axes", "interface:A", "interface:B", "cardona"}) {
    const Superelement se = ReduceWithFrame(frame);
    EXPECT_EQ(se.floating_frame.type, frame);
    EXPECT_LT(FrameIdentityError(se), 1e-10) << frame;
  }
}

TEST(FloatingFrame, CenterOfMassFrameIsTheMidpointMaterialPoint) {
  // Symmetric rod: the CoM is the midpoint node. Phi_CB there = the midpoint's (u, theta) rows
  // of the basis, so an antisymmetric bending shape (interface B moved up, A down) leaves the
  // midpoint's displacement zero.
  const Superelement se = ReduceWithFrame("center_of_mass");
  EXPECT_LT((se.floating_frame.origin - Eigen::Vector3d(0.15, 0, 0)).norm(), 1e-14);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(se.n_reduced_dofs());
  q[1] = -1e-3;  // A.u_y
  q[7] = 1e-3;   // B.u_y
  const Eigen::VectorXd frame_motion = se.floating_frame.Phi_CB * q;
  EXPECT_NEAR(frame_motion[1], 0.0, 1e-15);
  // ... but a rotation theta_z of the midpoint: the chord turns by 2e-3 / 0.3 and the midpoint's
  // static-mode slope of a pure S-shape with clamped ends is 1.5x the chord rotation.
  EXPECT_NEAR(frame_motion[5], 1.5 * 2e-3 / 0.3, 1e-9);
}

TEST(FloatingFrame, MeanAxesCarryNoMomentumOfTheDeformation) {
  const Superelement se = ReduceWithFrame("mean_axes");
  // Phi_CB = M_rig^-1 Phi_rig0^T M: deformations with Phi_CB q = 0 have zero linear and angular
  // momentum about the frame: Phi_rig0^T M q = 0.
  const Eigen::MatrixXd Phi_rig0 = RigidBodyModes(se, se.floating_frame.origin);
  Eigen::FullPivLU<Eigen::MatrixXd> lu(se.floating_frame.Phi_CB);
  const Eigen::MatrixXd null_space = lu.kernel();
  EXPECT_LT((Phi_rig0.transpose() * se.M * null_space).norm(), 1e-12 * se.M.norm());
}

TEST(FloatingFrame, CardonaWeightsOfASymmetricBeamAreOneHalf) {
  const Superelement se = ReduceWithFrame("cardona");
  ASSERT_EQ(se.floating_frame.cardona_weights.size(), 2);
  EXPECT_NEAR(se.floating_frame.cardona_weights[0], 0.5, 1e-12);
  EXPECT_NEAR(se.floating_frame.cardona_weights[1], 0.5, 1e-12);
  EXPECT_LT((se.floating_frame.origin - Eigen::Vector3d(0.15, 0, 0)).norm(), 1e-12);
}

TEST(FloatingFrame, InterfaceFrameSitsOnTheNode) {
  const Superelement se = ReduceWithFrame("interface:B");
  EXPECT_LT((se.floating_frame.origin - Eigen::Vector3d(0.3, 0, 0)).norm(), 1e-15);
  EXPECT_EQ(se.floating_frame.Phi_CB.block(0, 6, 6, 6), Eigen::MatrixXd::Identity(6, 6));
}

// Reduces `yaml` and returns the refusal's message, checking that no stage after the model's
// (factorization, modes, projection) was reported before it: the refusal needs the mesh and the
// mass alone, and a large part should not be factored first to hear it.
std::string RefusalBeforeTheFactorization(const std::string& yaml) {
  std::vector<std::string> stages;
  const std::string message = test::ThrownMessage([&] {
    ReducePart(ParsePart(yaml, "test.yaml"),
               [&](const std::string& stage, double, const std::string&) { stages.push_back(stage); });
  });
  EXPECT_FALSE(stages.empty());
  for (const std::string& stage : stages) {
    EXPECT_TRUE(stage == "mesh" || stage == "couplings" || stage == "assembly" || stage == "mesh+assembly")
        << "stage '" << stage << "' reported before the refusal";
  }
  return message;
}

// A solid ring (a short tube): its centre of mass is on the axis, in the bore.
TEST(FloatingFrame, CenterOfMassInTheBoreOfASolidRingIsRefusedBeforeTheFactorization) {
  const std::string yaml =
      "name: ring\ntype: solid\nmaterial: {E: 2.0e11, nu: 0.3, rho: 7870}\n"
      "geometry: {shape: tube, radius: 0.05, inner_radius: 0.03, length: 0.02}\n"
      "mesh: {size: 0.01, order: 1}\n"
      "interfaces: [{name: a, group: bottom, coupling: rbe3}, {name: b, group: top, coupling: rbe3}]\n"
      "reduction: {floating_frame: center_of_mass, internal_modes: 2}\n";
  const std::string message = RefusalBeforeTheFactorization(yaml);
  EXPECT_NE(message.find("test.yaml:7: reduction.floating_frame"), std::string::npos) << message;
  EXPECT_NE(message.find("lies outside the material; use floating_frame: mean_axes"), std::string::npos) << message;
}

TEST(FloatingFrame, CenterOfMassOutsideTheMaterialIsRefusedWithAHint) {
  // An L-shaped beam: its centre of mass lies off both legs.
  const std::string yaml =
      "name: ell\ntype: beam\nmaterial: {E: 2.0e11, nu: 0.3, rho: 7870}\n"
      "section: {shape: circle, diameter: 0.006}\n"
      "beam:\n  points: {A: [0, 0, 0], C: [0.2, 0, 0], B: [0.2, 0.2, 0]}\n"
      "  segments: [{from: A, to: C, elements: 4}, {from: C, to: B, elements: 4}]\n"
      "interfaces: [{name: A}, {name: B}]\n"
      "reduction: {floating_frame: center_of_mass, internal_modes: 2}\n";
  const std::string message = RefusalBeforeTheFactorization(yaml);
  EXPECT_NE(message.find("test.yaml:9: reduction.floating_frame"), std::string::npos) << message;
  EXPECT_NE(message.find("outside the material; use floating_frame: mean_axes"), std::string::npos) << message;
  // mean_axes works there.
  const Superelement se = test::Reduce(yaml, {"reduction.floating_frame=mean_axes"});
  EXPECT_LT(FrameIdentityError(se), 1e-10);
  EXPECT_LT((se.mass_properties.center_of_mass - Eigen::Vector3d(0.15, 0.05, 0)).norm(), 1e-12);
}

}  // namespace
}  // namespace femb
