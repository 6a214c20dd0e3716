// solver/joints/loop_constraints: the cut joints' equations assembled into the system, on models
// of nodes alone (no bodies), against definitions outside the assembly:
//   - G (the `jacobian` output) is the derivative of the constraint values -g, which the
//     multipliers' rows of the residual hold, by central differences of the node placements;
//   - the coordinate rows of the residual are -G^T lambda, and the tangent's coordinate block
//     the derivative of G^T lambda (central differences);
//   - a cut joint's reaction on its child is the force and moment whose virtual work on any
//     motion of the child alone is -lambda^T G dq (the child's columns);
//   - the violation is the largest kept equation, rotations scaled by the model's size, and
//     LoopsClosed compares it with the tolerance times that size;
//   - a planar four-bar of spatial revolutes keeps 2 of its cut joint's 5 equations (the other 3
//     are the plane's), and is named at its dead point (crank and coupler aligned) only;
//   - a loop whose drives leave it no free coordinate is refused, not opened.
#include "solver/joints/loop_constraints.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "formats/input_error.h"
#include "solver/assembly/system.h"
#include "solver/rotation.h"

namespace femb {
namespace {

using Vec6 = Eigen::Matrix<double, 6, 1>;

const JointType kTypes[6] = {JointType::kRigid,       JointType::kRevolute,  JointType::kPrismatic,
                             JointType::kCylindrical, JointType::kSpherical, JointType::kUniversal};

// Two free nodes p and c joined by a cut joint of `type`; c starts at its place in the joint.
SystemModel TwoFreeNodes(JointType type) {
  SystemModel model;
  AddNode(model, "p", Eigen::Vector3d(0.2, -0.1, 0.3), ExpSO3(Eigen::Vector3d(0.3, -0.5, 0.2)));
  AddNode(model, "c", Eigen::Vector3d(0.6, 0.2, 0.1), ExpSO3(Eigen::Vector3d(-0.2, 0.4, 0.7)));
  CutJoint cut;
  cut.joint = MakeNodeJoint(type, 1, 0, Eigen::Vector3d(0.36, 0.48, 0.8), model.node_x0[0], model.node_R0[0],
                            model.node_x0[1], model.node_R0[1], Eigen::Vector3d(0.8, 0, -0.36));
  cut.name = "cut";
  for (int i = 0; i < ConstraintCount(type); ++i) cut.equations.push_back(i);
  model.cut_joints.push_back(cut);
  model.Number();
  return model;
}

SystemState Moved(const SystemModel& model, const SystemState& s0, const Eigen::VectorXd& d) {
  SystemState s = s0;
  ApplyIncrement(model, model.dofs(), d, s);
  return s;
}

// The residual of the loops alone at s (coordinate rows -G^T lambda, multiplier rows -g).
Eigen::VectorXd LoopResidual(const SystemModel& model, const SystemState& s) {
  Eigen::VectorXd r = Eigen::VectorXd::Zero(model.dofs().n_dofs());
  AddLoopConstraints(model, model.dofs(), s, &r, nullptr, nullptr);
  return r;
}

// An opened state: both nodes moved, multipliers set.
SystemState Opened(const SystemModel& model, std::mt19937& rng) {
  const DofMap& dofs = model.dofs();
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::VectorXd d(dofs.n_dofs());
  for (int i = 0; i < d.size(); ++i) d[i] = dofs.multiplier(i) ? 30.0 * u(rng) : 0.1 * u(rng);
  return Moved(model, InitialState(model), d);
}

TEST(LoopConstraints, JacobianResidualAndTangentAreTheirDefinitions) {
  std::mt19937 rng(1);
  for (JointType type : kTypes) {
    const SystemModel model = TwoFreeNodes(type);
    const DofMap& dofs = model.dofs();
    const int n = dofs.n_dofs(), m = dofs.n_multipliers(), c = dofs.first_multiplier();
    ASSERT_EQ(m, ConstraintCount(type));
    const SystemState s = Opened(model, rng);
    Eigen::VectorXd r = Eigen::VectorXd::Zero(n);
    Triplets tangent, jacobian;
    AddLoopConstraints(model, dofs, s, &r, &tangent, nullptr, &jacobian);
    const Eigen::MatrixXd K(ToMatrix(n, tangent)), G(ToMatrix(n, jacobian));
    // G sits in the multipliers' rows and, transposed, in their columns.
    EXPECT_EQ((G.topRightCorner(c, m) - G.bottomLeftCorner(m, c).transpose()).norm(), 0.0);
    const Eigen::VectorXd lambda = s.lambda;
    EXPECT_LT((r.head(c) + G.bottomLeftCorner(m, c).transpose() * lambda).norm(), 1e-12 * (1 + r.norm()));
    const double h = 1e-6;
    for (int j = 0; j < c; ++j) {
      Eigen::VectorXd e = Eigen::VectorXd::Zero(n);
      e[j] = h;
      const Eigen::VectorXd fd =
          (LoopResidual(model, Moved(model, s, e)) - LoopResidual(model, Moved(model, s, -e))) / (2 * h);
      // The multipliers' rows: -g, so -dg/dq = -G.
      EXPECT_LT((fd.tail(m) + G.bottomLeftCorner(m, c).col(j)).norm(), 1e-8) << Name(type) << " column " << j;
      // The coordinate rows: -G^T lambda; the tangent (of -r) holds its derivative.
      EXPECT_LT((fd.head(c) + K.topLeftCorner(c, c).col(j)).norm(), 1e-6 * (1 + fd.head(c).norm()))
          << Name(type) << " column " << j;
    }
  }
}

TEST(LoopConstraints, CutJointReactionDoesTheMultipliersVirtualWork) {
  std::mt19937 rng(2);
  for (JointType type : kTypes) {
    const SystemModel model = TwoFreeNodes(type);
    const DofMap& dofs = model.dofs();
    const SystemState s = Opened(model, rng);
    const std::vector<Vec6> R = CutJointReactions(model, s);
    ASSERT_EQ(R.size(), 1u);
    // Virtual work on each motion of the child alone (its 6 coordinates: dx, spatial dpi).
    const int first = dofs.node_first(1), m = dofs.n_multipliers();
    const double h = 1e-6;
    for (int i = 0; i < 6; ++i) {
      Eigen::VectorXd e = Eigen::VectorXd::Zero(dofs.n_dofs());
      e[first + i] = h;
      const Eigen::VectorXd dg =
          -(LoopResidual(model, Moved(model, s, e)) - LoopResidual(model, Moved(model, s, -e))).tail(m) / (2 * h);
      EXPECT_NEAR(R[0][i], -s.lambda.dot(dg), 1e-7 * (1 + R[0].norm())) << Name(type) << " direction " << i;
    }
  }
}

TEST(LoopConstraints, ViolationIsTheLargestEquationWithRotationsScaled) {
  const SystemModel model = TwoFreeNodes(JointType::kRigid);
  const DofMap& dofs = model.dofs();
  const double L = BoundingDiagonal(model.node_x0);
  const SystemState s0 = InitialState(model);
  EXPECT_LT(LoopViolation(model, s0), 1e-15);
  EXPECT_TRUE(LoopsClosed(model, s0, 1e-15));
  // The child moved by 1e-3 along the parent's axis: the position equation along a is 1e-3.
  const Eigen::Vector3d a = s0.R[0] * model.cut_joints[0].joint.axis;
  Eigen::VectorXd d = Eigen::VectorXd::Zero(dofs.n_dofs());
  d.segment<3>(dofs.node_first(1)) = 1e-3 * a;
  int worst = -2;
  EXPECT_NEAR(LoopViolation(model, Moved(model, s0, d), &worst), 1e-3, 1e-15);
  EXPECT_EQ(worst, 0);
  // Turned by 1e-4 rad about a: the (b1, b2) dot product is sin(1e-4), times L.
  d.setZero();
  d.segment<3>(dofs.node_first(1) + 3) = 1e-4 * a;
  const SystemState turned = Moved(model, s0, d);
  EXPECT_NEAR(LoopViolation(model, turned), std::sin(1e-4) * L, 1e-12 * L);
  EXPECT_TRUE(LoopsClosed(model, turned, 1.01e-4));
  EXPECT_FALSE(LoopsClosed(model, turned, 0.99e-4));
  // No loops: nothing to close.
  SystemModel open = model;
  open.cut_joints.clear();
  open.Number();
  EXPECT_EQ(LoopViolation(open, InitialState(open)), 0.0);
  EXPECT_TRUE(LoopsClosed(open, InitialState(open), 0.0));
}

// Crank A-B (length a) on a revolute to the ground at the origin, coupler B-C (b), rocker D-C (c)
// on a revolute to the ground at D = (d, 0), all axes z, the crank at angle theta; the coupler
// meets the rocker at C through a cut revolute. Nodes only: B and C are rigid offsets of their
// links' pivots (B1 of A, C1 of B2, C2 of D). The rocker is driven (its angle prescribed), so
// the loop is at a dead point where crank and coupler are in one line.
SystemModel FourBar(double theta, double a = 0.3, double b = 0.9, double c = 0.7, double d = 1.0) {
  const Eigen::Vector3d A(0, 0, 0), B(a * std::cos(theta), a * std::sin(theta), 0), D(d, 0, 0);
  const double e = (B - D).norm(), x = (c * c - b * b + e * e) / (2 * e), y = std::sqrt(std::max(c * c - x * x, 0.0));
  const Eigen::Vector3d u = (B - D) / e, v(-u.y(), u.x(), 0);
  // Of the two places of C, the one farther from A (the crank and coupler stretched out).
  const Eigen::Vector3d C1 = D + x * u + y * v, C2 = D + x * u - y * v;
  const Eigen::Vector3d C = C1.norm() >= C2.norm() ? C1 : C2;
  SystemModel model;
  for (const auto& [name, p] :
       {std::pair<const char*, Eigen::Vector3d>{"A", A}, {"B1", B}, {"B2", B}, {"C1", C}, {"D", D}, {"C2", C}})
    AddNode(model, name, p);
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  RevoluteToGround(model, 0, z);
  RevoluteToGround(model, 4, z);
  model.joints.push_back(MakeNodeJoint(JointType::kRigid, 1, 0, z, A, I, B, I));
  model.joints.push_back(MakeNodeJoint(JointType::kRevolute, 2, 1, z, B, I, B, I));
  model.joints.push_back(MakeNodeJoint(JointType::kRigid, 3, 2, z, B, I, C, I));
  model.joints.push_back(MakeNodeJoint(JointType::kRigid, 5, 4, z, D, I, C, I));
  CutJoint cut;
  cut.joint = MakeNodeJoint(JointType::kRevolute, 5, 3, z, C, I, C, I);
  cut.name = "revolute joint between nodes 'C1' and 'C2'";
  cut.equations = {0, 1, 2, 3, 4};
  model.cut_joints.push_back(cut);
  model.prescribed.push_back(
      {4, 0, [](double) { return 0.0; }, [](double) { return 0.0; }, [](double) { return 0.0; }});
  model.Number();
  return model;
}

TEST(LoopConstraints, PlanarFourBarKeepsTwoEquationsAndIsNamedAtItsDeadPoint) {
  SystemModel model = FourBar(M_PI / 3);
  const std::vector<std::string> dropped = DropRedundantEquations(model);
  ASSERT_EQ(dropped.size(), 1u);
  EXPECT_FALSE(dropped[0].empty());
  // Kept: the two in-plane position equations (across the axis); dropped: the translation along
  // the axis and the two tilts of the axis, which the plane holds.
  EXPECT_EQ(model.cut_joints[0].equations, (std::vector<int>{1, 2}));
  EXPECT_EQ(model.dofs().n_multipliers(), 2);
  EXPECT_EQ(LoopSingularity(model, InitialState(model)), "");
  // Crank and coupler in one line (|C - A| = a + b with C on the rocker's circle): the kept
  // equations' columns of the crank and the coupler angles are parallel.
  const double a = 0.3, b = 0.9, c = 0.7, d = 1.0;
  // C at distance a + b from A and c from D: the crank angle where B lies on AC.
  const double r = a + b, cos_phi = (r * r + d * d - c * c) / (2 * r * d);
  SystemModel dead = FourBar(std::acos(cos_phi), a, b, c, d);
  dead.cut_joints[0].equations = model.cut_joints[0].equations;  // those kept at the generic place
  dead.Number();
  const std::string message = LoopSingularity(dead, InitialState(dead));
  EXPECT_EQ(message.rfind("revolute joint between nodes 'C1' and 'C2': the loop it closes is at or near a singular", 0),
            0u)
      << message;
}

// Both the crank and the rocker driven: the loop has no coordinate left to follow the drives, so
// an equation the solved coordinates cannot move is still moved by the drives (dropped, the loop
// would open as they turn). Refused, naming the cut joint and the driven nodes.
TEST(LoopConstraints, ALoopThatLocksItsDrivesIsRefused) {
  SystemModel model = FourBar(M_PI / 3);
  model.prescribed.push_back(
      {0, 0, [](double t) { return t; }, [](double) { return 1.0; }, [](double) { return 0.0; }});
  std::string message;
  try {
    DropRedundantEquations(model);
  } catch (const InputError& e) {
    message = e.what();
  }
  EXPECT_EQ(message.rfind("revolute joint between nodes 'C1' and 'C2': the loop it closes locks the drive of node ", 0),
            0u)
      << message;
  EXPECT_NE(message.find("'A'"), std::string::npos) << message;
  EXPECT_NE(message.find("'D'"), std::string::npos) << message;
}

}  // namespace
}  // namespace femb
