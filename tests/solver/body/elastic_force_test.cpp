// solver/body/elastic_force: the elastic force is the gradient of the strain energy, and the
// tangent K1+K2+K3(+K4) is its derivative (both checked by central finite differences), both
// invariant under rigid motions; small deformations give the reduced stiffness back.
#include "solver/body/elastic_force.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "body_test_util.h"
#include "solver/body/superelement_body.h"
#include "solver/rotation.h"
#include "test_util.h"

namespace femb {
namespace {

using namespace body_test;

struct Evaluation {
  Eigen::VectorXd f;
  double energy;
};

Evaluation ElasticAt(const SuperelementBody& body, const BodyConfiguration& c, FrameSolution guess) {
  const FrameSolution frame = SolveFrame(body, c, guess);
  EXPECT_TRUE(frame.ok);
  Evaluation e;
  ElasticForce(body, test::Lvalue(Evaluate(body, c, frame)), &e.f, nullptr);
  e.energy = ElasticEnergy(body, test::Lvalue(Evaluate(body, c, frame)));
  return e;
}

void CheckAgainstFiniteDifferences(const Superelement& se, const SuperelementOptions& options, double size) {
  const SuperelementBody body(se, options);
  const BodyConfiguration c = Deformed(body, size, 42);
  const FrameSolution frame = SolveFrame(body, c, GuessFrame(body, c));
  ASSERT_TRUE(frame.ok);
  Eigen::VectorXd f;
  Eigen::MatrixXd K;
  ElasticForce(body, test::Lvalue(Evaluate(body, c, frame)), &f, &K);
  const int n = body.n_coordinates();
  Eigen::MatrixXd K_fd(n, n);
  Eigen::VectorXd f_fd(n);
  for (int i = 0; i < n; ++i) {
    const Eigen::VectorXd e = Eigen::VectorXd::Unit(n, i);
    // Node coordinates: 1e-6 (m, rad). Modal coordinates are mass-normalized: one unit moves the
    // body by ~1/sqrt(mass), so their step is 1e-6 of the body size in displacement (a 2 g leaf:
    // 2e-9); a coordinate that turns the floating frame strongly (a thin leaf's torsion mode) gets
    // a proportionally smaller one.
    double extent = 0.0;
    for (const InterfaceNode& node : se.interfaces)
      extent = std::max(extent, (node.position - se.mass_properties.center_of_mass).norm());
    const double h = (i < se.n_interface_dofs() ? 1e-6 : 1e-6 * extent * std::sqrt(se.mass_properties.mass)) /
                     std::max(1.0, se.floating_frame.Phi_CB.col(i).norm());
    const Evaluation plus = ElasticAt(body, Perturb(c, e, h), frame);
    const Evaluation minus = ElasticAt(body, Perturb(c, e, -h), frame);
    K_fd.col(i) = (plus.f - minus.f) / (2 * h);
    f_fd[i] = (plus.energy - minus.energy) / (2 * h);
  }
  // Central differences: truncation O(h^2), round-off O(eps |f| / h): 1e-6 relative is ample.
  EXPECT_LT((K - K_fd).norm(), 1e-6 * K.norm())
      << "tangent, approximated=" << options.approximated << "\nK - K_fd (max) " << (K - K_fd).cwiseAbs().maxCoeff();
  if (!options.approximated) {
    // The force is the gradient of the strain energy.
    EXPECT_LT((f - f_fd).norm(), 1e-6 * f.norm()) << "force vs energy gradient";
  }
  EXPECT_GT(f.norm(), 0.0);
}

TEST(SuperelementBody, ExactTangentMatchesFiniteDifferences) {
  for (const std::string frame : {"center_of_mass", "mean_axes", "interface:A", "cardona"}) {
    SCOPED_TRACE(frame);
    CheckAgainstFiniteDifferences(Rod(frame), {false, true}, 0.3);
  }
  CheckAgainstFiniteDifferences(Tee(), {false, true}, 0.3);
}

TEST(SuperelementBody, ApproximatedTransformationTangentMatchesFiniteDifferences) {
  CheckAgainstFiniteDifferences(Rod("center_of_mass"), {true, true}, 0.3);
  CheckAgainstFiniteDifferences(Tee(), {true, true}, 0.3);
}

TEST(SuperelementBody, PolynomialInternalForceTangentMatchesFiniteDifferences) {
  // A solid leaf spring with modal derivatives: the local force is the Green-Lagrange polynomial;
  // force = energy gradient and the full tangent (its Hessian in K1, K2-K4 from the force) are
  // checked like the linear body's, and the polynomial changes the force.
  const Superelement se = test::Reduce(
      "name: leaf\ntype: solid\nmaterial: {E: 2.1e11, nu: 0.3, rho: 7850}\n"
      "geometry: {shape: box, size: [0.05, 0.01, 0.0005]}\n"
      "mesh: {size: 0.0025, order: 2, elements: hexahedra}\n"
      "interfaces: [{name: A, group: xmin}, {name: B, group: xmax}]\n"
      "reduction: {internal_modes: 2, modal_derivatives: {pairs: [[8, 8], [7, 7], [8, 12]]}}\n");
  ASSERT_TRUE(se.polynomial.has_value());
  ASSERT_EQ(se.n_modal_derivatives, 3);
  {
    SuperelementOptions lin;
    lin.polynomial_force = false;
    SCOPED_TRACE("linear");
    CheckAgainstFiniteDifferences(se, lin, 0.05);
  }
  CheckAgainstFiniteDifferences(se, {false, true}, 0.05);
  CheckAgainstFiniteDifferences(se, {true, true}, 0.05);
  SuperelementOptions linear;
  linear.polynomial_force = false;
  const SuperelementBody with(se, {}), without(se, linear);
  const BodyConfiguration c = Deformed(with, 0.05, 3);
  const FrameSolution frame = SolveFrame(with, c, GuessFrame(with, c));
  Eigen::VectorXd f1, f2;
  ElasticForce(with, test::Lvalue(Evaluate(with, c, frame)), &f1, nullptr);
  ElasticForce(without, test::Lvalue(Evaluate(without, c, frame)), &f2, nullptr);
  EXPECT_GT((f1 - f2).norm(), 1e-3 * f2.norm());
}

TEST(SuperelementBody, TangentIsSymmetricAtEquilibriumFreeConfiguration) {
  // The exact force is a gradient, so its derivative (a Hessian) is symmetric everywhere.
  const SuperelementBody body(Rod("center_of_mass"), {false, true});
  const BodyConfiguration c = Deformed(body, 0.2, 7);
  const FrameSolution frame = SolveFrame(body, c, GuessFrame(body, c));
  Eigen::VectorXd f;
  Eigen::MatrixXd K;
  ElasticForce(body, test::Lvalue(Evaluate(body, c, frame)), &f, &K);
  // A Hessian on SO(3) with spatial variations is symmetric up to the term (f_moment x) — the
  // asymmetric part is bounded by the moments: check it is small relative to K.
  EXPECT_LT((K - K.transpose()).norm(), 1e-3 * K.norm());
}

TEST(SuperelementBody, RigidMotionsAreForceFreeAndForcesRotateWithTheBody) {
  const Superelement se = Rod("center_of_mass");
  const SuperelementBody body(se, {false, true});
  BodyConfiguration c0 = InitialConfiguration(body);
  Eigen::VectorXd f;
  ElasticForce(body, test::Lvalue(Evaluate(body, c0, SolveFrame(body, c0, body.InitialFrame()))), &f, nullptr);
  EXPECT_LT(f.norm(), 1e-12);
  // Rigid motion of the undeformed body: still no force; frame follows.
  const Eigen::Matrix3d Rr = ExpSO3(Eigen::Vector3d(2.0, -0.5, 1.0));
  const Eigen::Vector3d t(1, 2, 3);
  BodyConfiguration moved = c0;
  for (int k = 0; k < body.n_nodes(); ++k) {
    moved.x[k] = Rr * c0.x[k] + t;
    moved.R[k] = Rr * c0.R[k];
  }
  const FrameSolution frame = SolveFrame(body, moved, GuessFrame(body, moved));
  ASSERT_TRUE(frame.ok);
  ElasticForce(body, test::Lvalue(Evaluate(body, moved, frame)), &f, nullptr);
  EXPECT_LT(f.norm(), 1e-14 * se.K.cwiseAbs().maxCoeff());  // round-off of positions ~3 m
  EXPECT_LT((frame.R - Rr).norm(), 1e-12);
  EXPECT_LT((frame.x - (Rr * body.InitialFrame().x + t)).norm(), 1e-12);
  // A deformed configuration moved rigidly: same energy, forces rotated.
  const BodyConfiguration d = Deformed(body, 0.2, 3);
  BodyConfiguration dm = d;
  for (int k = 0; k < body.n_nodes(); ++k) {
    dm.x[k] = Rr * d.x[k] + t;
    dm.R[k] = Rr * d.R[k];
  }
  Eigen::VectorXd fd, fdm;
  const FrameSolution a = SolveFrame(body, d, GuessFrame(body, d)), b = SolveFrame(body, dm, GuessFrame(body, dm));
  ElasticForce(body, test::Lvalue(Evaluate(body, d, a)), &fd, nullptr);
  ElasticForce(body, test::Lvalue(Evaluate(body, dm, b)), &fdm, nullptr);
  EXPECT_NEAR(ElasticEnergy(body, test::Lvalue(Evaluate(body, d, a))),
              ElasticEnergy(body, test::Lvalue(Evaluate(body, dm, b))),
              1e-10 * ElasticEnergy(body, test::Lvalue(Evaluate(body, d, a))));
  for (int k = 0; k < 2 * body.n_nodes(); ++k) {
    EXPECT_LT((Rr * fd.segment<3>(3 * k) - fdm.segment<3>(3 * k)).norm(), 1e-9 * fd.norm());
  }
  // Total force and moment about the origin of the elastic forces vanish (internal forces).
  Eigen::Vector3d F = Eigen::Vector3d::Zero(), Mo = Eigen::Vector3d::Zero();
  for (int k = 0; k < body.n_nodes(); ++k) {
    F += fd.segment<3>(6 * k);
    Mo += fd.segment<3>(6 * k + 3) + d.x[k].cross(fd.segment<3>(6 * k));
  }
  EXPECT_LT(F.norm(), 1e-9 * fd.norm());
  EXPECT_LT(Mo.norm(), 1e-9 * fd.norm());
}

TEST(SuperelementBody, SmallDeformationsReproduceTheReducedStiffness) {
  // About the undeformed placement the tangent is Rbar K Rbar^T for deformation directions
  // (K1 = T^T K T with T removing rigid motions, thesis 3.25, and K2 = K3 = 0 with no load).
  const Superelement se = Rod("center_of_mass");
  const Eigen::Matrix3d Rp = ExpSO3(Eigen::Vector3d(0.3, 0.2, -0.4));
  const SuperelementBody body(se, {false, true}, Rp, Eigen::Vector3d(1, 0, 0));
  const BodyConfiguration c = InitialConfiguration(body);
  Eigen::MatrixXd Kt;
  Eigen::VectorXd f;
  ElasticForce(body, test::Lvalue(Evaluate(body, c, SolveFrame(body, c, body.InitialFrame()))), &f, &Kt);
  const int n = body.n_coordinates();
  Eigen::MatrixXd Rbar = Eigen::MatrixXd::Identity(n, n);
  for (int a = 0; a < 2 * body.n_nodes(); ++a) Rbar.block<3, 3>(3 * a, 3 * a) = Rp;
  EXPECT_LT((Kt - Rbar * se.K * Rbar.transpose()).norm(), 1e-9 * se.K.norm());
}

}  // namespace
}  // namespace femb
