// solver/joints/joint_tree: the tree's kinematics and statics on a chain of every joint type
// with offsets (no bodies), against definitions outside the tree's own formulas:
//   - node velocities J_k W are the time derivatives of the node placements along a motion
//     q(t) = q0 (+) (t W + t^2 Wdot / 2) (central differences of the positions and rotations);
//   - node accelerations (J Wdot + the joints' convective terms) are the time derivatives of the
//     node velocities along the same motion;
//   - the convective terms' derivative in W and the accelerations' derivative in q are the
//     central differences of NodeAccelerations;
//   - the reactions are the statics of the tree: each held node takes minus the forces on it and
//     on everything below it, moments taken about it, a ball joint passing force but no moment
//     (rigid-body statics, written out here);
//   - the joints' geometric stiffness is the derivative of sum_k J_k^T f_k at fixed f.
#include "solver/joints/joint_tree.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "solver/assembly/system.h"
#include "solver/rotation.h"

namespace femb {
namespace {

using Vec6 = Eigen::Matrix<double, 6, 1>;

// ground -universal- n0 -revolute- n1 -prismatic- n2 -spherical- n3 -cylindrical- n4 -rigid- n5,
// and a free node n6 carrying n7 on a revolute joint; every axis oblique, every offset nonzero.
SystemModel Chain() {
  SystemModel model;
  const Eigen::Vector3d x[8] = {{0.1, 0.0, 0.2}, {0.5, 0.1, 0.2}, {0.8, 0.3, 0.1},  {1.0, 0.2, 0.0},
                                {1.2, 0.4, 0.3}, {1.3, 0.5, 0.3}, {-0.4, 0.3, 0.1}, {-0.7, 0.1, 0.5}};
  for (int k = 0; k < 8; ++k) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(0.3 * k, Eigen::Vector3d(1, k, 2).normalized()).toRotationMatrix();
    AddNode(model, "n" + std::to_string(k), x[k], R);
  }
  const auto joint = [&](JointType type, int child, int parent, const Eigen::Vector3d& axis,
                         const Eigen::Vector3d& axis2 = Eigen::Vector3d::UnitY()) {
    const Eigen::Vector3d x_p = parent == kGround ? Eigen::Vector3d::Zero() : model.node_x0[size_t(parent)];
    const Eigen::Matrix3d R_p = parent == kGround ? Eigen::Matrix3d::Identity() : model.node_R0[size_t(parent)];
    model.joints.push_back(MakeNodeJoint(type, child, parent, axis.normalized(), x_p, R_p, model.node_x0[size_t(child)],
                                         model.node_R0[size_t(child)], axis2.normalized()));
  };
  joint(JointType::kUniversal, 0, kGround, Eigen::Vector3d(0, 0.3, 1), Eigen::Vector3d(1, 0.2, 0));
  joint(JointType::kRevolute, 1, 0, Eigen::Vector3d(0.2, 1, 0.1));
  joint(JointType::kPrismatic, 2, 1, Eigen::Vector3d(1, 1, 0));
  joint(JointType::kSpherical, 3, 2, Eigen::Vector3d::UnitZ());
  joint(JointType::kCylindrical, 4, 3, Eigen::Vector3d(1, 0, 0.4));
  joint(JointType::kRigid, 5, 4, Eigen::Vector3d::UnitZ());
  joint(JointType::kRevolute, 7, 6, Eigen::Vector3d(0.5, -1, 0.3));
  model.Number();
  return model;
}

Eigen::VectorXd Random(int n, std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v[i] = u(rng);
  return v;
}

// The state reached from s0 by the increment d (ApplyIncrement: joint coordinates add, free and
// spherical rotations compose spatially).
SystemState Moved(const SystemModel& model, const SystemState& s0, const Eigen::VectorXd& d) {
  SystemState s = s0;
  ApplyIncrement(model, model.dofs(), d, s);
  return s;
}

struct Motion {
  SystemModel model = Chain();
  SystemState s0;
  Eigen::VectorXd W, Wdot;
  Motion() {
    std::mt19937 rng(3);
    const int n = model.dofs().n_dofs();
    s0 = Moved(model, InitialState(model), Random(n, rng, 0.4));  // a generic configuration
    W = Random(n, rng, 2.0);
    Wdot = Random(n, rng, 5.0);
  }
  SystemState At(double t) const { return Moved(model, s0, t * W + 0.5 * t * t * Wdot); }
  Eigen::VectorXd VelocityAt(double t) const { return W + t * Wdot; }
};

// (x(t + h) - x(t - h)) / 2h and the spatial angular velocity log(R(t + h) R(t - h)^T) / 2h.
Vec6 PlacementRate(const SystemState& plus, const SystemState& minus, int k, double h) {
  Vec6 v;
  v.head<3>() = (plus.x[size_t(k)] - minus.x[size_t(k)]) / (2 * h);
  v.tail<3>() = LogSO3(Eigen::Matrix3d(plus.R[size_t(k)] * minus.R[size_t(k)].transpose())) / (2 * h);
  return v;
}

TEST(JointTree, NodeVelocitiesAreThePlacementsRates) {
  const Motion m;
  const double h = 1e-5;
  const SystemState plus = m.At(h), minus = m.At(-h);
  for (int k = 0; k < m.model.n_nodes(); ++k) {
    const Vec6 v = NodeMotion(m.s0, k, m.W);
    const Vec6 fd = PlacementRate(plus, minus, k, h);
    EXPECT_LT((v - fd).norm(), 1e-8 * (1 + v.norm()))
        << "node " << k << ": " << v.transpose() << " vs " << fd.transpose();
  }
  EXPECT_EQ(NodeMotion(m.s0, kGround, m.W), Vec6::Zero());
}

TEST(JointTree, NodeAccelerationsAreTheVelocitiesRates) {
  const Motion m;
  const DofMap& dofs = m.model.dofs();
  const std::vector<Vec6> acc = NodeAccelerations(m.model, dofs, m.s0, m.W, m.Wdot);
  const double h = 1e-5;
  const SystemState plus = m.At(h), minus = m.At(-h);
  double largest = 0;
  for (int k = 0; k < m.model.n_nodes(); ++k) {
    const Vec6 fd = (NodeMotion(plus, k, m.VelocityAt(h)) - NodeMotion(minus, k, m.VelocityAt(-h))) / (2 * h);
    EXPECT_LT((acc[size_t(k)] - fd).norm(), 1e-6 * (1 + fd.norm())) << "node " << k;
    largest = std::max(largest, (acc[size_t(k)] - NodeMotion(m.s0, k, m.Wdot)).norm());
  }
  EXPECT_GT(largest, 1.0);  // the convective terms are not small here: the test sees them
}

TEST(JointTree, AccelerationDerivativesAreTheirDifferences) {
  const Motion m;
  const DofMap& dofs = m.model.dofs();
  const int n = dofs.n_dofs();
  std::vector<NodeJacobian> dc, dq;
  ConvectiveVelocityDerivative(m.model, dofs, m.s0, m.W, dc);
  NodeAccelerationConfigurationDerivative(m.model, dofs, m.s0, m.W, m.Wdot, dq);
  const auto dense = [&](const std::vector<NodeJacobian>& D, int k) {
    Eigen::MatrixXd out = Eigen::MatrixXd::Zero(6, n);
    if (size_t(k) < D.size()) {
      for (const auto& [col, v] : D[size_t(k)]) out.col(col) += v;
    }
    return out;
  };
  const double h = 1e-6;
  for (int j = 0; j < n; ++j) {
    Eigen::VectorXd e = Eigen::VectorXd::Zero(n);
    e[j] = h;
    // In W: the convective terms are quadratic in W, Wdot enters linearly through J only.
    const std::vector<Vec6> a_plus = NodeAccelerations(m.model, dofs, m.s0, m.W + e, m.Wdot);
    const std::vector<Vec6> a_minus = NodeAccelerations(m.model, dofs, m.s0, m.W - e, m.Wdot);
    // In q, at fixed W and Wdot.
    const SystemState q_plus = Moved(m.model, m.s0, e), q_minus = Moved(m.model, m.s0, -e);
    const std::vector<Vec6> c_plus = NodeAccelerations(m.model, dofs, q_plus, m.W, m.Wdot);
    const std::vector<Vec6> c_minus = NodeAccelerations(m.model, dofs, q_minus, m.W, m.Wdot);
    for (int k = 0; k < m.model.n_nodes(); ++k) {
      const Vec6 fd_w = (a_plus[size_t(k)] - a_minus[size_t(k)]) / (2 * h);
      EXPECT_LT((dense(dc, k).col(j) - fd_w).norm(), 1e-7 * (1 + fd_w.norm())) << "W, node " << k << " col " << j;
      const Vec6 fd_q = (c_plus[size_t(k)] - c_minus[size_t(k)]) / (2 * h);
      EXPECT_LT((dense(dq, k).col(j) - fd_q).norm(), 1e-6 * (1 + fd_q.norm())) << "q, node " << k << " col " << j;
    }
  }
}

// Forces (F, M) on every node: the universal joint's child n0 takes minus all of them with the
// moments about n0; n3 (spherical, under n2) minus those on n3, n4, n5 about n3; a free node
// takes none, its revolute child n7 minus its own.
TEST(JointTree, ReactionsAreTheStaticsOfTheTree) {
  const Motion m;
  const DofMap& dofs = m.model.dofs();
  std::mt19937 rng(5);
  NodeForces forces = ZeroNodeForces(m.model);
  for (int k = 0; k < m.model.n_nodes(); ++k) forces.Add(k, Random(6, rng, 10.0));
  const std::vector<Vec6> R = JointReactions(m.model, dofs, m.s0, forces);
  const auto below = [&](int top, std::initializer_list<int> nodes) {
    Vec6 t = Vec6::Zero();
    for (int k : nodes) {
      t.head<3>() += forces.f[size_t(k)].head<3>();
      t.tail<3>() += forces.f[size_t(k)].tail<3>() +
                     (m.s0.x[size_t(k)] - m.s0.x[size_t(top)]).cross(Eigen::Vector3d(forces.f[size_t(k)].head<3>()));
    }
    return Vec6(-t);
  };
  // Through n3's spherical joint its subtree's force passes at n3, its moment not at all (a ball
  // joint carries none): n0 takes n0..n2 as they are and the subtree's force at n3.
  Vec6 through_ball = below(0, {0, 1, 2});
  const Eigen::Vector3d F_ball = (forces.f[3] + forces.f[4] + forces.f[5]).head<3>();
  through_ball.head<3>() -= F_ball;
  through_ball.tail<3>() -= (m.s0.x[3] - m.s0.x[0]).cross(F_ball);
  EXPECT_LT((R[0] - through_ball).norm(), 1e-12 * 100);
  EXPECT_LT((R[3] - below(3, {3, 4, 5})).norm(), 1e-12 * 100);
  EXPECT_LT((R[5] - below(5, {5})).norm(), 1e-12 * 100);
  EXPECT_LT((R[7] - below(7, {7})).norm(), 1e-12 * 100);
  EXPECT_EQ(R[6], Vec6::Zero());
}

// The joints' geometric stiffness: tangent -= d(sum_k J_k^T f_k)/dq at fixed node forces f.
TEST(JointTree, GeometricStiffnessIsTheDerivativeOfTheMappedForces) {
  const Motion m;
  const DofMap& dofs = m.model.dofs();
  const int n = dofs.n_dofs();
  std::mt19937 rng(9);
  NodeForces forces = ZeroNodeForces(m.model);
  for (int k = 0; k < m.model.n_nodes(); ++k) forces.Add(k, Random(6, rng, 10.0));
  Triplets t;
  AddJointGeometricStiffness(m.model, dofs, m.s0, forces, t);
  const Eigen::MatrixXd K = Eigen::MatrixXd(ToMatrix(n, t));
  const auto mapped = [&](const SystemState& s) {
    Eigen::VectorXd g = Eigen::VectorXd::Zero(n);
    for (int k = 0; k < m.model.n_nodes(); ++k) {
      for (const auto& [col, v] : s.J[size_t(k)]) g[col] += v.dot(forces.f[size_t(k)]);
    }
    return g;
  };
  const double h = 1e-6;
  for (int j = 0; j < n; ++j) {
    Eigen::VectorXd e = Eigen::VectorXd::Zero(n);
    e[j] = h;
    const Eigen::VectorXd fd = (mapped(Moved(m.model, m.s0, e)) - mapped(Moved(m.model, m.s0, -e))) / (2 * h);
    EXPECT_LT((-K.col(j) - fd).norm(), 1e-6 * (1 + fd.norm())) << "column " << j;
  }
}

}  // namespace
}  // namespace femb
