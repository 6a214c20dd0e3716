// solver/assembly/system_model: the model's supports, prescribed coordinates, initial state and
// the gathering of a body's configuration, against closed forms (the numbering of the unknowns
// and the increments are in system_test.cpp):
//   - a revolute support driven by phi(t) = sin(2 t) turns its node to exp(phi a~) R0 and sets its
//     rate and acceleration, a prismatic one moves it by s(t) a, whatever the state before;
//   - a node is fixed to the ground through rigid joints only, down any chain;
//   - the model's size is the diagonal of its nodes' bounding box;
//   - the initial state places the nodes, zeroes the modes and multipliers, and its Jacobians are
//     the identity on a free node and the axis on a revolute;
//   - a body's configuration holds its own nodes' placements, in its order, and its modes.
#include "solver/assembly/system_model.h"

#include <gtest/gtest.h>

#include <cmath>

#include "solver/joints/joint_tree.h"
#include "solver/rotation.h"
#include "test_util.h"

namespace femb {
namespace {

using Vec6 = Eigen::Matrix<double, 6, 1>;

TEST(SystemModel, PrescribedSupportsFollowTheirFunctions) {
  SystemModel model;
  const Eigen::Vector3d a = Eigen::Vector3d(0.36, 0.48, 0.8);
  const Eigen::Matrix3d R0 = ExpSO3(Eigen::Vector3d(0.3, -0.2, 0.5));
  AddNode(model, "turned", Eigen::Vector3d(0.1, 0.2, 0.3), R0);
  AddNode(model, "slid", Eigen::Vector3d(1.0, 0.0, 0.0), R0);
  RevoluteToGround(model, 0, a);
  PrismaticToGround(model, 1, a);
  model.prescribed.push_back({0, 0, [](double t) { return std::sin(2 * t); },
                              [](double t) { return 2 * std::cos(2 * t); },
                              [](double t) { return -4 * std::sin(2 * t); }});
  model.prescribed.push_back({1, 0, [](double t) { return 0.5 * t * t; }, [](double t) { return t; }, nullptr});
  model.Number();
  const DofMap& dofs = model.dofs();
  ASSERT_EQ(dofs.n_dofs(), 2);
  EXPECT_TRUE(dofs.solved().empty());
  SystemState state = InitialState(model);
  Eigen::VectorXd W = Eigen::VectorXd::Zero(2), Wdot = Eigen::VectorXd::Zero(2);
  for (const double t : {0.4, 1.7, -0.3}) {  // from wherever the state stood
    ApplyPrescribed(model, dofs, t, state, &W, &Wdot);
    EXPECT_LT((state.R[0] - ExpSO3(Eigen::Vector3d(std::sin(2 * t) * a)) * R0).norm(), 1e-14) << t;
    EXPECT_LT((state.x[0] - model.node_x0[0]).norm(), 1e-15) << t;  // a revolute support holds its node's place
    EXPECT_LT((state.x[1] - (model.node_x0[1] + 0.5 * t * t * a)).norm(), 1e-15) << t;
    EXPECT_LT((state.R[1] - R0).norm(), 1e-15) << t;
    EXPECT_EQ(W[dofs.prescribed_index(model.prescribed[0])], 2 * std::cos(2 * t));
    EXPECT_EQ(Wdot[dofs.prescribed_index(model.prescribed[0])], -4 * std::sin(2 * t));
    EXPECT_EQ(W[dofs.prescribed_index(model.prescribed[1])], t);
    EXPECT_EQ(Wdot[dofs.prescribed_index(model.prescribed[1])], 0.0);  // no acceleration function: 0
    // The node velocities the rates give: the revolute's omega = phidot a, the slider's v = sdot a.
    const Vec6 v0 = NodeMotion(state, 0, W), v1 = NodeMotion(state, 1, W);
    EXPECT_LT((v0.tail<3>() - 2 * std::cos(2 * t) * a).norm(), 1e-14);
    EXPECT_LT((v1.head<3>() - t * a).norm(), 1e-14);
  }
}

TEST(SystemModel, FixedToGroundOnlyThroughRigidJoints) {
  SystemModel model;
  for (int k = 0; k < 5; ++k) AddNode(model, "n" + std::to_string(k), Eigen::Vector3d(k, 0, 0));
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  Clamp(model, 0);  // n0 clamped; n1 rigid on n0; n2 revolute on n1; n3 rigid on n2; n4 free
  model.joints.push_back(
      MakeNodeJoint(JointType::kRigid, 1, 0, Eigen::Vector3d::UnitZ(), model.node_x0[0], I, model.node_x0[1], I));
  model.joints.push_back(
      MakeNodeJoint(JointType::kRevolute, 2, 1, Eigen::Vector3d::UnitZ(), model.node_x0[1], I, model.node_x0[2], I));
  model.joints.push_back(
      MakeNodeJoint(JointType::kRigid, 3, 2, Eigen::Vector3d::UnitZ(), model.node_x0[2], I, model.node_x0[3], I));
  model.Number();
  EXPECT_TRUE(FixedToGround(model, 0));
  EXPECT_TRUE(FixedToGround(model, 1));
  EXPECT_FALSE(FixedToGround(model, 2));
  EXPECT_FALSE(FixedToGround(model, 3));
  EXPECT_FALSE(FixedToGround(model, 4));
  Pin(model, 4);  // a pin leaves the rotation free
  EXPECT_FALSE(FixedToGround(model, 4));
  Clamp(model, 4);  // and a clamp replaces it
  EXPECT_TRUE(FixedToGround(model, 4));
  EXPECT_EQ(std::count_if(model.joints.begin(), model.joints.end(), [](const NodeJoint& j) { return j.child == 4; }),
            1);
}

TEST(SystemModel, SizeIsTheBoundingBoxDiagonal) {
  EXPECT_EQ(BoundingDiagonal({}), 0.0);
  EXPECT_EQ(BoundingDiagonal({Eigen::Vector3d(1, 2, 3)}), 0.0);
  EXPECT_DOUBLE_EQ(BoundingDiagonal({Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(-2, 6, 3), Eigen::Vector3d(0, 3, 15)}),
                   std::sqrt(9.0 + 16.0 + 144.0));
}

TEST(SystemModel, InitialStateAndABodysConfiguration) {
  const Superelement tube = test::TubeSegment(0.5, 4, false);
  SystemModel model;
  const Eigen::Matrix3d R = ExpSO3(Eigen::Vector3d(0, 0, 0.4));
  AddNode(model, "hub", Eigen::Vector3d(0.2, 0, 0), R);
  AddNode(model, "far", Eigen::Vector3d(0.2, 0, 0) + 0.5 * R.col(0), R);
  AddNode(model, "tip", Eigen::Vector3d(0.2, 0, 0) + R.col(0), R);
  for (int b = 0; b < 2; ++b) {
    model.bodies.emplace_back(tube, SuperelementOptions{}, R, model.node_x0[size_t(b)]);
    model.body_nodes.push_back({b, b + 1});  // body 0: hub, far; body 1: far, tip
  }
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  RevoluteToGround(model, 0, z);
  model.Number();
  const SystemState s = InitialState(model);
  const DofMap& dofs = model.dofs();
  ASSERT_EQ(s.x.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(s.x[size_t(k)], model.node_x0[size_t(k)]);
    EXPECT_EQ(s.R[size_t(k)], model.node_R0[size_t(k)]);
    EXPECT_EQ(s.z[size_t(k)].size(), dofs.node_count(k));
    EXPECT_EQ(s.z[size_t(k)].squaredNorm(), 0.0);
  }
  for (int b = 0; b < 2; ++b) {
    EXPECT_EQ(s.eta[size_t(b)].size(), model.bodies[size_t(b)].n_modes());
    EXPECT_EQ(s.eta[size_t(b)].squaredNorm(), 0.0);
    EXPECT_EQ(s.frames[size_t(b)].x, model.bodies[size_t(b)].InitialFrame().x);
  }
  EXPECT_EQ(s.lambda.size(), 0);
  // The revolute's Jacobian: its axis on the rotation rows, about a node at its own place.
  ASSERT_EQ(s.J[0].size(), 1u);
  EXPECT_EQ(s.J[0][0].first, 0);
  EXPECT_LT((s.J[0][0].second - (Vec6() << 0, 0, 0, z).finished()).norm(), 1e-15);
  // A free node's Jacobian: the identity on its own six coordinates.
  ASSERT_EQ(s.J[2].size(), 6u);
  for (int i = 0; i < 6; ++i) {
    EXPECT_EQ(s.J[2][size_t(i)].first, dofs.node_first(2) + i);
    EXPECT_EQ(s.J[2][size_t(i)].second, Vec6::Unit(i));
  }
  // Body 1's nodes (far, tip), and its modes.
  SystemState moved = s;
  moved.eta[1] = Eigen::VectorXd::LinSpaced(moved.eta[1].size(), 1.0, 2.0);
  moved.x[2] += Eigen::Vector3d(0, 0.01, 0);
  const BodyConfiguration c = BodyConfigurationOf(model, moved, 1);
  ASSERT_EQ(c.x.size(), 2u);
  EXPECT_EQ(c.x[0], moved.x[1]);
  EXPECT_EQ(c.x[1], moved.x[2]);
  EXPECT_EQ(c.R[1], moved.R[2]);
  EXPECT_EQ(c.eta, moved.eta[1]);
  BodyConfiguration reused = c;
  BodyConfigurationOf(model, s, 0, reused);  // into existing storage: body 0's (hub, far)
  EXPECT_EQ(reused.x[0], s.x[0]);
  EXPECT_EQ(reused.x[1], s.x[1]);
  EXPECT_EQ(reused.eta, s.eta[0]);
}

}  // namespace
}  // namespace femb
