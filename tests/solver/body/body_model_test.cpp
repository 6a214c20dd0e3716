// solver/body/body_model: a rigid body is its own kind of body model (SuperelementBody::Rigid), one
// node at its centre of mass that is its own floating frame. Against Newton-Euler's closed forms
// for a rigid body turned by R with spatial velocity (v, omega) and acceleration (a, alpha), J_w =
// R J R^T the inertia in world axes:
//   T = m |v|^2 / 2 + omega . J_w omega / 2,
//   f_in = [m a; J_w alpha + omega x J_w omega],
// and the momenta p = m v, L = x x m v + J_w omega about the origin; and it is the same model as
// the one-node superelement with Phi_CB = 1 that stood for a rigid body before (every member to
// the bit).
#include "solver/body/body_model.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "solver/body/superelement_body.h"
#include "solver/rotation.h"
#include "test_util.h"

namespace femb {
namespace {

MassProperties Block() {
  MassProperties p;
  p.mass = 2.5;
  p.center_of_mass = Eigen::Vector3d(0.1, -0.2, 0.05);
  p.inertia_com << 0.04, 0.002, -0.001, 0.002, 0.03, 0.003, -0.001, 0.003, 0.05;
  return p;
}

TEST(BodyModel, RigidBodyFollowsNewtonEuler) {
  const MassProperties p = Block();
  const Eigen::Matrix3d R = ExpSO3(Eigen::Vector3d(0.3, -0.7, 1.1));
  const Eigen::Vector3d x(1.0, 2.0, -0.5);
  const SuperelementBody body = SuperelementBody::Rigid(p, R, x);
  EXPECT_EQ(body.kind(), BodyKind::kRigid);
  ASSERT_EQ(body.n_coordinates(), 6);
  EXPECT_EQ(body.mass(), p.mass);
  // Its node is the centre of mass, placed and turned; the frame is the node's.
  const BodyConfiguration c0 = InitialConfiguration(body);
  EXPECT_LT((c0.x[0] - (x + R * p.center_of_mass)).norm(), 1e-15);
  // A turned configuration and a motion.
  BodyConfiguration c = c0;
  c.R[0] = ExpSO3(Eigen::Vector3d(-0.4, 0.2, 0.9)) * c.R[0];
  c.x[0] += Eigen::Vector3d(0.3, 0.1, -0.2);
  const FrameSolution frame = SolveFrame(body, c, GuessFrame(body, c));
  ASSERT_TRUE(frame.ok);
  EXPECT_LT((frame.x - c.x[0]).norm(), 1e-14);
  const Eigen::Matrix3d Jw = c.R[0] * p.inertia_com * c.R[0].transpose();
  Eigen::VectorXd w(6), wdot(6);
  w << 0.5, -1.0, 2.0, 3.0, -2.0, 1.5;
  wdot << -4.0, 1.0, 0.5, 10.0, 7.0, -3.0;
  const Eigen::Vector3d v = w.head<3>(), omega = w.tail<3>(), a = wdot.head<3>(), alpha = wdot.tail<3>();
  BodyData d = Evaluate(body, c, frame);
  const double T = 0.5 * p.mass * v.squaredNorm() + 0.5 * omega.dot(Jw * omega);
  EXPECT_NEAR(KineticEnergy(body, d, w), T, 1e-13 * T);
  Eigen::VectorXd f;
  InertiaForce(body, d, w, wdot, &f, nullptr, nullptr);
  Eigen::VectorXd newton_euler(6);
  newton_euler << p.mass * a, Jw * alpha + omega.cross(Jw * omega);
  EXPECT_LT((f - newton_euler).norm(), 1e-12 * newton_euler.norm()) << f.transpose() << "\n"
                                                                    << newton_euler.transpose();
  Eigen::Vector3d linear, angular;
  Momentum(body, d, w, &linear, &angular);
  EXPECT_LT((linear - p.mass * v).norm(), 1e-13 * p.mass * v.norm());
  const Eigen::Vector3d L = c.x[0].cross(p.mass * v) + Jw * omega;
  EXPECT_LT((angular - L).norm(), 1e-13 * L.norm());
  // The centre of mass is the node, and a rigid body has no elastic force.
  EXPECT_LT((CenterOfMass(body, d.q, frame) - c.x[0]).norm(), 1e-14);
  Eigen::VectorXd f_el;
  ElasticForce(body, d, &f_el, nullptr);
  EXPECT_EQ(f_el.norm(), 0.0);
}

// The model Rigid makes is the one-node superelement with Phi_CB = 1 and the rigid mass that a
// rigid body was before it had a kind of its own: every member to the bit.
TEST(BodyModel, RigidIsTheOneNodeSuperelementItReplaced) {
  const MassProperties p = Block();
  const Eigen::Matrix3d R = ExpSO3(Eigen::Vector3d(0.3, -0.7, 1.1));
  const Eigen::Vector3d x(1.0, 2.0, -0.5);
  Superelement se;
  se.name = "block";
  se.interfaces.push_back({"com", p.center_of_mass, Eigen::Matrix3d::Identity()});
  se.K = Eigen::MatrixXd::Zero(6, 6);
  se.M = Eigen::MatrixXd::Zero(6, 6);
  se.M.topLeftCorner(3, 3) = p.mass * Eigen::Matrix3d::Identity();
  se.M.bottomRightCorner(3, 3) = p.inertia_com;
  se.floating_frame.origin = p.center_of_mass;
  se.floating_frame.Phi_CB = Eigen::MatrixXd::Identity(6, 6);
  se.mass_properties = p;
  const SuperelementBody old(se, SuperelementOptions{}, R, x);
  const SuperelementBody rigid = SuperelementBody::Rigid(p, R, x);
  EXPECT_EQ(old.kind(), BodyKind::kSuperelement);
  EXPECT_EQ(rigid.K_, old.K_);
  EXPECT_EQ(rigid.M_, old.M_);
  EXPECT_EQ(rigid.Phi_CB_, old.Phi_CB_);
  EXPECT_EQ(rigid.Phi_rig0_, old.Phi_rig0_);
  EXPECT_EQ(rigid.C_.rows(), 0);
  EXPECT_EQ(rigid.C_.cols(), old.C_.cols());
  EXPECT_EQ(rigid.T0_, old.T0_);
  EXPECT_EQ(rigid.X_, old.X_);
  EXPECT_EQ(rigid.R0_, old.R0_);
  EXPECT_EQ(rigid.mass_, old.mass_);
  EXPECT_EQ(rigid.first_moment0_, old.first_moment0_);
  EXPECT_EQ(rigid.first_moment_map_, old.first_moment_map_);
  EXPECT_EQ(rigid.force_weights_, old.force_weights_);
  EXPECT_EQ(rigid.force_floor_, old.force_floor_);
  EXPECT_EQ(rigid.k_max_, old.k_max_);
  EXPECT_EQ(rigid.m_max_, old.m_max_);
  EXPECT_EQ(rigid.modal_weight_, old.modal_weight_);
  EXPECT_EQ(rigid.initial_frame_.x, old.initial_frame_.x);
  EXPECT_EQ(rigid.initial_frame_.R, old.initial_frame_.R);
  EXPECT_EQ(rigid.has_exact_inertia(), old.has_exact_inertia());
  EXPECT_EQ(rigid.has_inertia_stiffening(), old.has_inertia_stiffening());
}

}  // namespace
}  // namespace femb
