// Joints between nodes: the static tangent of a system with every joint type (including the
// joints' geometric stiffness) against central finite differences of the residual, exact
// constraint satisfaction, the convective terms through the energy balance of a flexible
// double pendulum, and supports as joints to the ground.
#include "solver/joints/node_joint.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "solver/analysis/dynamic_analysis.h"
#include "solver/assembly/system.h"
#include "solver/joints/joint_tree.h"
#include "solver/rotation.h"
#include "test_util.h"

namespace femb {
namespace {

Superelement Rod(double L, int modes, const std::string& frame = "center_of_mass") {
  return test::Reduce(
      "name: rod\ntype: beam\nmaterial: {E: 2.0e9, nu: 0.3, rho: 7800}\n"
      "section: {shape: circle, diameter: 0.02}\n"
      "beam:\n  points: {A: [0, 0, 0], B: [" +
      std::to_string(L) +
      ", 0, 0]}\n"
      "  segments: [{from: A, to: B, elements: 4}]\n"
      "interfaces: [{name: A}, {name: B}]\nreduction: {internal_modes: " +
      std::to_string(modes) + ", floating_frame: " + frame + ", geometric_stiffening: false}\n");
}

// A chain of six rods, node pairs at the joints: revolute (axis z), prismatic (axis x),
// spherical, cylindrical (axis y), universal (axes z, y). The first node is clamped.
SystemModel Chain(const Superelement& se, double L) {
  SystemModel model;
  const JointType types[5] = {JointType::kRevolute, JointType::kPrismatic, JointType::kSpherical,
                              JointType::kCylindrical, JointType::kUniversal};
  const Eigen::Vector3d axes[5] = {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitZ(),
                                   Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()};
  AddNode(model, "n0", Eigen::Vector3d::Zero());
  for (int b = 0; b < 6; ++b) {
    const Eigen::Vector3d x0(b * L, 0, 0);
    if (b > 0) AddNode(model, "c" + std::to_string(b), x0);  // child at the body start
    const int start = model.n_nodes() - 1;
    AddNode(model, "e" + std::to_string(b), x0 + Eigen::Vector3d(L, 0, 0));
    model.bodies.emplace_back(se, SuperelementOptions{}, Eigen::Matrix3d::Identity(), x0);
    model.body_nodes.push_back({start, start + 1});
    if (b > 0) {
      const int parent = start - 1, child = start;
      model.joints.push_back(MakeNodeJoint(types[b - 1], child, parent, axes[b - 1], model.node_x0[parent],
                                           model.node_R0[parent], model.node_x0[child], model.node_R0[child],
                                           Eigen::Vector3d::UnitY()));
    }
  }
  Clamp(model, 0);
  NodeLoad follower;
  follower.node = model.n_nodes() - 1;
  follower.force = Eigen::Vector3d(10, -20, 15);
  follower.moment = Eigen::Vector3d(1, 2, -1);
  follower.follower = true;
  model.loads.push_back(follower);
  NodeLoad fixed;
  fixed.node = 4;
  fixed.force = Eigen::Vector3d(-5, 30, 7);
  model.loads.push_back(fixed);
  model.Number();
  return model;
}

TEST(NodeJoint, StaticTangentWithEveryJointTypeMatchesFiniteDifferences) {
  const double L = 0.5;
  const Superelement se = Rod(L, 2);
  const SystemModel model = Chain(se, L);
  const DofMap dofs(model);
  SystemState state = InitialState(model);
  // A deformed, displaced configuration.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::VectorXd shift(dofs.n_dofs());
  for (int i = 0; i < shift.size(); ++i) shift[i] = 0.05 * u(rng);
  ApplyIncrement(model, dofs, shift, state);
  SystemForces f0 = AssembleStatic(model, dofs, state, 1.0, true);
  ASSERT_TRUE(f0.ok);
  const int n = dofs.n_dofs();
  const Eigen::MatrixXd K_fd = test::StaticTangentByDifferences(model, dofs, state, 1.0);
  const double error = (f0.tangent - K_fd).norm() / K_fd.norm();
  std::printf("[ info ] %d coordinates, relative tangent error %.2e\n", n, error);
  EXPECT_LT(error, 1e-6);
}

TEST(NodeJoint, ConstraintsHoldExactlyAtAnyConfiguration) {
  const double L = 0.5;
  const SystemModel model = Chain(Rod(L, 0), L);
  const DofMap dofs(model);
  SystemState s = InitialState(model);
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int rep = 0; rep < 5; ++rep) {
    Eigen::VectorXd d(dofs.n_dofs());
    for (int i = 0; i < d.size(); ++i) d[i] = 0.5 * u(rng);
    ApplyIncrement(model, dofs, d, s);
  }
  // Revolute c1 on e0: same point, relative rotation about the parent's z axis only. The clamp
  // of the first node is a rigid joint to the ground (ParentOf: the origin, world axes).
  for (const NodeJoint& j : model.joints) {
    const ParentNode parent = ParentOf(s, j.parent);
    const Eigen::Matrix3d rel = parent.R.transpose() * s.R[j.child];
    const Eigen::Vector3d offset = parent.R.transpose() * (s.x[j.child] - parent.x);
    if (j.type == JointType::kRigid) {
      EXPECT_LT((rel - j.Q0).norm(), 1e-12);
      EXPECT_LT((offset - j.r0).norm(), 1e-12);
    }
    if (j.type == JointType::kRevolute) {
      EXPECT_LT(offset.norm(), 1e-12);
      EXPECT_LT((rel * j.axis - j.axis).norm(), 1e-12);  // the axis is fixed in both
    }
    if (j.type == JointType::kPrismatic) {
      EXPECT_LT((rel - Eigen::Matrix3d::Identity()).norm(), 1e-12);
      EXPECT_LT(offset.cross(j.axis).norm(), 1e-12);  // travel along the axis only
    }
    if (j.type == JointType::kSpherical) {
      EXPECT_LT(offset.norm(), 1e-12);
    }
    if (j.type == JointType::kCylindrical) {
      EXPECT_LT(offset.cross(j.axis).norm(), 1e-12);
      EXPECT_LT((rel * j.axis - j.axis).norm(), 1e-12);
    }
    if (j.type == JointType::kUniversal) {
      // Same point; the child's second axis stays perpendicular to the parent's first axis.
      EXPECT_LT(offset.norm(), 1e-12);
      EXPECT_LT(std::abs(j.axis.dot(rel * j.Q0.transpose() * j.axis2)), 1e-12);
    }
  }
}

void DoublePendulum(JointType second, const Eigen::Vector3d& spin,
                    Integrator integrator = Integrator::kGeneralizedAlpha);

TEST(NodeJoint, FlexibleDoublePendulumConservesEnergy) {
  DoublePendulum(JointType::kRevolute, Eigen::Vector3d::Zero());
}

// The midpoint scheme on the same chain: its bodies have free nodes (n1, n3) and nodes on joints
// (n0 on the ground, n2 on n1), so the scheme's node velocities come from W for some and from
// the node motion for others (solver/integrators/midpoint.cpp). Measured: 2.8e-5 (2 ms), 4.0e-6 (1 ms).
TEST(NodeJoint, FlexibleDoublePendulumConservesEnergyWithTheMidpointScheme) {
  DoublePendulum(JointType::kRevolute, Eigen::Vector3d::Zero(), Integrator::kMidpoint);
}

TEST(NodeJoint, SpatialDoublePendulumWithAUniversalJointConservesEnergy) {
  // The second rod hangs from a universal joint (axes z and y) and starts with a spin about its
  // own axis, so that it swings out of the plane: the universal joint's convective terms matter.
  DoublePendulum(JointType::kUniversal, Eigen::Vector3d(3.0, 0, 0));
}

void DoublePendulum(JointType second, const Eigen::Vector3d& spin, Integrator integrator) {
  // Two 0.5 m rods: the first on a revolute joint to ground at n0 (axis z), the second hinged
  // to its tip by a revolute joint between nodes; gravity -y; released horizontal. Energy:
  // kinetic + elastic - work of gravity stays constant (rho_inf = 1); the joint's convective
  // accelerations are needed for that.
  const double L = 0.5;
  const Superelement se = Rod(L, 2);
  SystemModel model;
  AddNode(model, "n0", Eigen::Vector3d::Zero());
  AddNode(model, "n1", Eigen::Vector3d(L, 0, 0));
  AddNode(model, "n2", Eigen::Vector3d(L, 0, 0));
  AddNode(model, "n3", Eigen::Vector3d(2 * L, 0, 0));
  // As femb-solve builds them: the midpoint scheme's bodies have the corotational inertia.
  SuperelementOptions options;
  options.exact_inertia = integrator != Integrator::kMidpoint;
  model.bodies.emplace_back(se, options, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  model.body_nodes.push_back({0, 1});
  model.bodies.emplace_back(se, options, Eigen::Matrix3d::Identity(), Eigen::Vector3d(L, 0, 0));
  model.body_nodes.push_back({2, 3});
  RevoluteToGround(model, 0, Eigen::Vector3d::UnitZ());
  model.joints.push_back(MakeNodeJoint(second, 2, 1, Eigen::Vector3d::UnitZ(), model.node_x0[1], model.node_R0[1],
                                       model.node_x0[2], model.node_R0[2], Eigen::Vector3d::UnitY()));
  model.gravity = Eigen::Vector3d(0, -9.81, 0);
  double max_z = 0;
  auto run = [&](double h, double* drift, double* min_y) {
    model.Number();
    const DofMap dofs(model);
    Eigen::VectorXd W0 = Eigen::VectorXd::Zero(dofs.n_dofs());
    if (spin.squaredNorm() > 0) {
      // Joint rates giving the second rod's tip the out-of-plane velocity spin x (L, 0, 0).
      W0[dofs.node_first(2) + 1] = spin.x();
    }
    DynamicState s = InitialDynamicState(model, InitialState(model), W0);
    const DynamicStepReport r0 = Measure(model, s);
    DynamicOptions run_options;
    run_options.step = h;
    run_options.end_time = 1.0;
    run_options.rho_inf = 1.0;
    run_options.integrator = integrator;
    *drift = 0;
    *min_y = 0;
    const double scale = 2 * se.mass_properties.mass * 9.81 * L;  // energy scale
    const DynamicResult result =
        SolveDynamic(model, s, run_options, [&](const DynamicStepReport& r, const DynamicState& st) {
          const double E = r.kinetic_energy + r.elastic_energy - r.external_work;
          *drift = std::max(*drift, std::abs(E - (r0.kinetic_energy + r0.elastic_energy)) / scale);
          *min_y = std::min(*min_y, st.config.x[3].y());
          max_z = std::max(max_z, std::abs(st.config.x[3].z()));
          // The hinge: nodes n1 and n2 coincide exactly.
          EXPECT_LT((st.config.x[1] - st.config.x[2]).norm(), 1e-12);
        });
    EXPECT_TRUE(result.ok) << result.message;
  };
  double drift_coarse, drift_fine, y_coarse, y_fine;
  run(2e-3, &drift_coarse, &y_coarse);
  run(1e-3, &drift_fine, &y_fine);
  std::printf("[ info ] energy error / (2 m g L): %.2e (h = 2 ms), %.2e (1 ms); lowest tip y %.4f m\n", drift_coarse,
              drift_fine, y_fine);
  EXPECT_LT(y_fine, -0.5);  // it swings down
  // and out of the plane (measured 0.043 m; planar motion would keep z at round-off)
  if (second == JointType::kUniversal) {
    EXPECT_GT(max_z, 0.01);
  }
  EXPECT_LT(drift_fine, 1e-3);
  EXPECT_GT(drift_coarse / drift_fine, 3.0);  // second order: the error is the integrator's
}

// A support is a joint to the ground (kGround: the fixed parent at the origin,
// world axes). Each type's node Jacobian is the motion basis supports had before (revolute
// [0; a], prismatic [a; 0], cylindrical both, pin [0; 1], universal [0; a1], [0; a2]), and a
// flexible rod hanging on it moves exactly as on the same joint to a clamped node at the joint
// (the tree's general path, with the parent's placement, Jacobian and motion): the tip's path
// under gravity over 0.2 s equal to 1e-12 m, the two computing the same quantities in another
// order. Clamps and rigid joints on clamped nodes cannot move (FixedToGround).
TEST(NodeJoint, SupportsAreJointsToTheGroundAndMoveAsOnAClampedNode) {
  const double L = 0.5;
  const Superelement se = Rod(L, 2);
  const Eigen::Vector3d a = Eigen::Vector3d(0.36, 0.48, 0.8), a2 = Eigen::Vector3d(0.8, 0, -0.36);
  const Eigen::Vector3d x0(0.1, -0.2, 0.3);
  const Eigen::Matrix3d R0 = ExpSO3(Eigen::Vector3d(0.2, -0.1, 0.4));
  for (const JointType type : {JointType::kRevolute, JointType::kPrismatic, JointType::kCylindrical,
                               JointType::kSpherical, JointType::kUniversal}) {
    SCOPED_TRACE(int(type));
    // to_clamped: the same joint on a clamped node at the joint, world axes.
    auto make = [&](bool to_clamped) {
      SystemModel model;
      AddNode(model, "n0", x0, R0);
      AddNode(model, "n1", x0 + R0 * Eigen::Vector3d(L, 0, 0), R0);
      model.bodies.emplace_back(se, SuperelementOptions{}, R0, x0);
      model.body_nodes.push_back({0, 1});
      if (to_clamped) {
        const int g = AddNode(model, "g", x0);
        Clamp(model, g);
        model.joints.push_back(MakeNodeJoint(type, 0, g, a, x0, Eigen::Matrix3d::Identity(), x0, R0, a2));
      } else {
        JointToGround(model, type, 0, a, a2);
      }
      model.gravity = Eigen::Vector3d(0, -9.81, 0);
      model.Number();
      return model;
    };
    const SystemModel grounded = make(false), clamped = make(true);
    ASSERT_EQ(grounded.joints.size(), 1u);
    EXPECT_EQ(grounded.joints[0].parent, kGround);
    EXPECT_FALSE(FixedToGround(grounded, 0));
    EXPECT_TRUE(FixedToGround(clamped, 2));
    // The node Jacobian: the support's motion basis.
    const SystemState s0 = InitialState(grounded);
    const DofMap& dofs = grounded.dofs();
    Eigen::MatrixXd S = Eigen::MatrixXd::Zero(6, dofs.node_count(0));
    for (const auto& [col, v] : s0.J[0]) S.col(col - dofs.node_first(0)) = v;
    Eigen::MatrixXd expected(6, dofs.node_count(0));
    const Eigen::Vector3d z = Eigen::Vector3d::Zero(), u = a.normalized(), u2 = a2.normalized();
    if (type == JointType::kRevolute) expected << z, u;
    if (type == JointType::kPrismatic) expected << u, z;
    if (type == JointType::kCylindrical) expected << u, z, z, u;
    if (type == JointType::kSpherical) expected << Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Identity();
    if (type == JointType::kUniversal) expected << z, z, u, u2;
    EXPECT_LT((S - expected).norm(), 1e-15) << S;
    // The motion: the same on both.
    std::vector<Eigen::Vector3d> tips[2];
    for (int m = 0; m < 2; ++m) {
      const SystemModel& model = m == 0 ? grounded : clamped;
      DynamicState s = InitialDynamicState(model, InitialState(model), Eigen::VectorXd::Zero(model.dofs().n_dofs()));
      DynamicOptions options;
      options.step = 2e-3;
      options.end_time = 0.2;
      const DynamicResult result =
          SolveDynamic(model, s, options,
                       [&](const DynamicStepReport&, const DynamicState& st) { tips[m].push_back(st.config.x[1]); });
      ASSERT_TRUE(result.ok) << result.message;
    }
    ASSERT_EQ(tips[0].size(), tips[1].size());
    double largest = 0, moved = 0;
    for (size_t i = 0; i < tips[0].size(); ++i) {
      largest = std::max(largest, (tips[0][i] - tips[1][i]).norm());
      moved = std::max(moved, (tips[0][i] - tips[0][0]).norm());
    }
    std::printf("[ info ] joint type %d to the ground: tip moved %.3f m, largest difference %.1e m\n", int(type), moved,
                largest);
    EXPECT_GT(moved, 0.01);  // it moves (falls, slides or swings)
    EXPECT_LT(largest, 1e-12);
  }
  // A clamp is a rigid joint to the ground; a rigid joint on a clamped node cannot move either.
  SystemModel model;
  AddNode(model, "c", Eigen::Vector3d::Zero());
  AddNode(model, "d", Eigen::Vector3d::UnitX());
  Clamp(model, 0);
  model.joints.push_back(MakeNodeJoint(JointType::kRigid, 1, 0, a, Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity(),
                                       Eigen::Vector3d::UnitX(), Eigen::Matrix3d::Identity()));
  EXPECT_EQ(model.joints[0].type, JointType::kRigid);
  model.Number();
  EXPECT_EQ(model.dofs().n_dofs(), 0);
  EXPECT_TRUE(FixedToGround(model, 0));
  EXPECT_TRUE(FixedToGround(model, 1));
}

}  // namespace
}  // namespace femb
