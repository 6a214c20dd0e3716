// Closed loops: cut joints imposed by constraint equations with Lagrange multipliers.
// The constraint Jacobian and the multipliers' geometric stiffness in the static tangent of every
// joint type against central finite differences of the residual (multipliers nonzero, the cut
// joint's parent hanging on a tree joint); a rigid four-bar driven at constant crank speed
// against its closed-form kinematics (Freudenstein: the intersection of two circles); the
// redundant equations of a planar loop of spatial revolute joints found and dropped; and what a
// bad loop gets.
#include "solver/joints/loop_closure.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "formats/input_error.h"
#include "formats/scene_file.h"
#include "solver/analysis/dynamic_analysis.h"
#include "solver/analysis/dynamic_step.h"
#include "solver/analysis/modal_analysis.h"
#include "solver/analysis/static_analysis.h"
#include "solver/assembly/system.h"
#include "solver/rotation.h"
#include "solver/scene/scene_builder.h"
#include "test_util.h"

namespace femb {
namespace {

Superelement Rod(double L, int modes) {
  return test::Reduce(
      "name: rod\ntype: beam\nmaterial: {E: 2.0e9, nu: 0.3, rho: 7800}\n"
      "section: {shape: circle, diameter: 0.02}\n"
      "beam:\n  points: {A: [0, 0, 0], B: [" +
      std::to_string(L) +
      ", 0, 0]}\n"
      "  segments: [{from: A, to: B, elements: 4}]\n"
      "interfaces: [{name: A}, {name: B}]\nreduction: {internal_modes: " +
      std::to_string(modes) + "}\n");
}

// Rod 0 clamped at n0; rod 1 hangs on rod 0's end through a tree revolute joint (node c1 child
// of e0); rod 2 starts at c1's place, turned by 90 degrees about z, with its own coordinates,
// and is joined to c1 by a cut joint of the given type (child c2, parent c1).
SystemModel Loop(const Superelement& se, double L, JointType type) {
  SystemModel model;
  const Eigen::Matrix3d turn = ExpSO3(Eigen::Vector3d(0, 0, M_PI / 2));
  AddNode(model, "n0", Eigen::Vector3d::Zero());
  AddNode(model, "e0", Eigen::Vector3d(L, 0, 0));
  AddNode(model, "c1", Eigen::Vector3d(L, 0, 0));
  AddNode(model, "e1", Eigen::Vector3d(2 * L, 0, 0));
  AddNode(model, "c2", Eigen::Vector3d(L, 0, 0), turn);
  AddNode(model, "e2", Eigen::Vector3d(L, L, 0), turn);
  for (int b = 0; b < 3; ++b) {
    const Eigen::Vector3d x0 = b == 0 ? Eigen::Vector3d::Zero() : Eigen::Vector3d(L, 0, 0);
    model.bodies.emplace_back(se, SuperelementOptions{}, b == 2 ? turn : Eigen::Matrix3d::Identity(), x0);
    model.body_nodes.push_back({2 * b, 2 * b + 1});
  }
  Clamp(model, 0);
  model.joints.push_back(MakeNodeJoint(JointType::kRevolute, 2, 1, Eigen::Vector3d(0, 0.6, 0.8), model.node_x0[1],
                                       model.node_R0[1], model.node_x0[2], model.node_R0[2]));
  CutJoint cut;
  cut.joint = MakeNodeJoint(type, 4, 2, Eigen::Vector3d(0.36, 0.48, 0.8), model.node_x0[2], model.node_R0[2],
                            model.node_x0[4], model.node_R0[4], Eigen::Vector3d(0.8, 0, -0.36));
  cut.name = "cut";
  for (int i = 0; i < ConstraintCount(type); ++i) cut.equations.push_back(i);
  model.cut_joints.push_back(cut);
  NodeLoad load;
  load.node = 5;
  load.force = Eigen::Vector3d(10, -20, 15);
  load.moment = Eigen::Vector3d(1, 2, -1);
  model.loads.push_back(load);
  model.Number();
  return model;
}

const char* JointName(JointType type) {
  const char* names[6] = {"rigid", "revolute", "prismatic", "cylindrical", "spherical", "universal"};
  return names[int(type)];
}

TEST(LoopClosure, ClosureAtThePlacementAndEquationCounts) {
  const int expected[6] = {6, 5, 5, 4, 3, 4};
  const JointType types[6] = {JointType::kRigid,       JointType::kRevolute,  JointType::kPrismatic,
                              JointType::kCylindrical, JointType::kSpherical, JointType::kUniversal};
  for (int t = 0; t < 6; ++t) {
    EXPECT_EQ(ConstraintCount(types[t]), expected[t]);
    EXPECT_EQ(ConstraintCount(types[t]),
              6 - MakeNodeJoint(types[t], 1, 0, Eigen::Vector3d::UnitZ(), Eigen::Vector3d::Zero(),
                                Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity())
                      .n_coordinates());
    const SystemModel model = Loop(Rod(0.5, 0), 0.5, types[t]);
    EXPECT_LT(LoopViolation(model, InitialState(model)), 1e-15);
  }
}

// A cut joint's coordinates from the placements (what a `joint` probe shows) against the tree
// joint's own: the child placed by PlaceChild at known coordinates, in a general pose (tilted
// axes, an offset placement), must give them back to round-off, angles beyond pi/2 included.
TEST(LoopClosure, CutJointCoordinatesGiveBackTheTreeJointsCoordinates) {
  const Eigen::Vector3d x_p(0.3, -0.2, 0.5), axis = Eigen::Vector3d(0.36, 0.48, 0.8), axis2(0.8, 0, -0.36);
  const Eigen::Matrix3d R_p = ExpSO3(Eigen::Vector3d(0.4, -1.1, 0.7)), R_c0 = ExpSO3(Eigen::Vector3d(-0.3, 0.2, 0.9));
  const Eigen::Vector3d x_c0 = x_p + R_p * Eigen::Vector3d(0.1, 0.2, -0.05);
  for (const JointType type :
       {JointType::kRevolute, JointType::kPrismatic, JointType::kCylindrical, JointType::kUniversal}) {
    const NodeJoint j = MakeNodeJoint(type, 1, 0, axis, x_p, R_p, x_c0, R_c0, axis2);
    for (const double scale : {0.3, 1.0, 2.9}) {
      Eigen::VectorXd z(j.n_coordinates());
      for (int i = 0; i < z.size(); ++i) z[i] = scale * (i == 0 ? 0.8 : -0.6);
      Eigen::Vector3d x_c;
      Eigen::Matrix3d R_c = R_c0;
      PlaceChild(j, x_p, R_p, z, &x_c, &R_c);
      const Eigen::VectorXd back = CutJointCoordinates(j, x_p, R_p, x_c, R_c);
      ASSERT_EQ(back.size(), z.size()) << JointName(type);
      EXPECT_LT((back - z).norm(), 1e-12) << JointName(type) << " at " << z.transpose();
    }
  }
}

TEST(LoopClosure, StaticTangentWithCutJointsMatchesFiniteDifferences) {
  const double L = 0.5;
  const Superelement se = Rod(L, 2);
  const JointType types[6] = {JointType::kRigid,       JointType::kRevolute,  JointType::kPrismatic,
                              JointType::kCylindrical, JointType::kSpherical, JointType::kUniversal};
  for (JointType type : types) {
    const SystemModel model = Loop(se, L, type);
    const DofMap dofs(model);
    ASSERT_EQ(dofs.n_multipliers(), ConstraintCount(type));
    SystemState state = InitialState(model);
    // A displaced configuration with the loop open by the displacement, and multipliers.
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1, 1);
    Eigen::VectorXd shift(dofs.n_dofs());
    for (int i = 0; i < shift.size(); ++i) shift[i] = dofs.multiplier(i) ? 50.0 * u(rng) : 0.05 * u(rng);
    ApplyIncrement(model, dofs, shift, state);
    ASSERT_GT(LoopViolation(model, state), 1e-3);
    const SystemForces f0 = AssembleStatic(model, dofs, state, 1.0, true);
    ASSERT_TRUE(f0.ok);
    const Eigen::MatrixXd K_fd = test::StaticTangentByDifferences(model, dofs, state, 1.0);
    const Eigen::MatrixXd K(f0.tangent);
    const int m = dofs.n_multipliers(), c = dofs.first_multiplier();
    const double error = (K - K_fd).norm() / K_fd.norm();
    const double g_error =
        (K.bottomLeftCorner(m, c) - K_fd.bottomLeftCorner(m, c)).norm() / K_fd.bottomLeftCorner(m, c).norm();
    std::printf("[ info ] %s cut joint: %d coordinates, %d multipliers; tangent error %.2e, constraint rows %.2e\n",
                JointName(type), c, m, error, g_error);
    EXPECT_LT(error, 1e-6);
    EXPECT_LT(g_error, 1e-6);
  }
}

using test::Number;

std::string Point(const Eigen::Vector2d& p) { return "[" + Number(p.x()) + ", " + Number(p.y()) + ", 0]"; }

// A rigid link from p to q in the xy plane: mass 2 kg per metre, a uniform rod's inertia about
// z (m L^2 / 12 about the centre), points P and Q on scene nodes np and nq.
std::string RigidLink(const std::string& name, const Eigen::Vector2d& p, const Eigen::Vector2d& q,
                      const std::string& np, const std::string& nq) {
  const double L = (q - p).norm(), m = 2.0 * L, I = m * L * L / 12;
  return "  - {name: " + name + ", type: rigid, mass: " + Number(m) + ", inertia: [" + Number(0.01 * I) + ", " +
         Number(I) + ", " + Number(I) + "], center_of_mass: " + Point(0.5 * (p + q)) + ", points: {P: " + Point(p) +
         ", Q: " + Point(q) + "}, nodes: {P: " + np + ", Q: " + nq + "}}\n";
}

// A crank-rocker four-bar in the xy plane: ground pivots A (origin) and D (d, 0); crank AB of
// length a, coupler BC of b, rocker DC of c; all links rigid, all joints spatial revolutes
// about z, the crank driven at omega. The scene's loop has one cut joint (femb picks it).
struct FourBar {
  double d = 1.0, a = 0.3, b = 0.9, c = 0.7, theta0 = M_PI / 2, omega = 2 * M_PI;
  // C for the crank angle theta: the intersection of |C - B| = b and |C - D| = c above AD.
  Eigen::Vector2d C(double theta) const {
    const Eigen::Vector2d B(a * std::cos(theta), a * std::sin(theta)), D(d, 0);
    const double e = (B - D).norm(), x = (c * c - b * b + e * e) / (2 * e), y = std::sqrt(c * c - x * x);
    const Eigen::Vector2d u = (B - D) / e, v(-u.y(), u.x());
    return D + x * u + y * v;  // the branch that starts above the ground line
  }
  std::string Scene(const std::string& analysis, const std::string& extra_joint_keys = "") const {
    const Eigen::Vector2d B(a * std::cos(theta0), a * std::sin(theta0)), Cp = C(theta0);
    return "name: four_bar\nunits: SI\nbodies:\n" + RigidLink("crank", Eigen::Vector2d::Zero(), B, "A", "B1") +
           RigidLink("coupler", B, Cp, "B2", "C1") + RigidLink("rocker", Eigen::Vector2d(d, 0), Cp, "D", "C2") +
           "joints:\n"
           "  - {type: revolute, node: A, axis: [0, 0, 1], prescribed: drive}\n"
           "  - {type: revolute, node: B2, parent: B1, axis: [0, 0, 1]}\n"
           "  - {type: revolute, node: C2, parent: C1, axis: [0, 0, 1]}\n"
           "  - {type: revolute, node: D, axis: [0, 0, 1]" +
           extra_joint_keys +
           "}\n"
           "functions:\n  drive: {type: linear, slope: " +
           Number(omega) + "}\n" + analysis;
  }
};

TEST(LoopClosure, RigidFourBarFollowsItsClosedFormKinematics) {
  const FourBar fb;
  const Scene scene =
      BuildScene(ParseScene(fb.Scene("analysis: {type: dynamic, end_time: 10, step: 1.0e-4}\n"), "four_bar.yaml"));
  const SystemModel& model = scene.model;
  ASSERT_EQ(model.cut_joints.size(), 1u);
  // The revolute at D closes the loop; 3 of its 5 equations are the plane's (redundant).
  EXPECT_EQ(model.cut_joints[0].equations.size(), 2u);
  bool noted = false;
  for (const std::string& note : scene.notes) {
    noted |= note.find(
                 "revolute joint of node 'D' to the ground closes a loop: 2 constraint equations with Lagrange "
                 "multipliers; 3 more (translation along the axis, rotation about (-1, 0, 0) of the parent's axes, "
                 "rotation about (0, -1, 0) of the parent's axes) repeat other constraints") != std::string::npos;
  }
  EXPECT_TRUE(noted) << (scene.notes.empty() ? std::string() : scene.notes.back());
  EXPECT_EQ(DofMap(model).n_multipliers(), 2);
  DynamicState s = InitialDynamicState(model, InitialState(model), scene.initial_velocity);
  DynamicOptions options;
  options.step = 1e-4;
  options.end_time = 10.0;  // ten crank turns in 1e5 steps: the constraint drift stays bounded
  const int C1 = scene.node_index.at("C1"), C2 = scene.node_index.at("C2"), B1 = scene.node_index.at("B1");
  double error = 0.0, violation = 0.0;
  const DynamicResult r = SolveDynamic(model, s, options, [&](const DynamicStepReport& rep, const DynamicState& st) {
    const double theta = fb.theta0 + fb.omega * rep.t;
    const Eigen::Vector2d C = fb.C(theta) - scene.origin.head<2>();
    const Eigen::Vector2d B = Eigen::Vector2d(fb.a * std::cos(theta), fb.a * std::sin(theta)) - scene.origin.head<2>();
    error = std::max({error, (st.config.x[C1].head<2>() - C).norm(), (st.config.x[B1].head<2>() - B).norm()});
    violation = std::max(violation, (st.config.x[C1] - st.config.x[C2]).norm());
  });
  ASSERT_TRUE(r.ok) << r.message;
  std::printf(
      "[ info ] rigid four-bar, ten crank turns in %ld steps: largest error of B, C %.2e m, joint C gap %.2e m, "
      "loop violation at the end %.2e m\n",
      r.steps, error, violation, LoopViolation(model, s.config));
  EXPECT_LT(error, 1e-8);  // the closed form, to 1e-8 of a 1 m mechanism
  EXPECT_LT(violation, 1e-8);
  EXPECT_LT(LoopViolation(model, s.config), 1e-12);
  EXPECT_EQ(r.steps, 100000);
}

// The dynamic iteration matrix of the moving four-bar (loop closed by multipliers, rigid links
// on offsets: a chain whose node accelerations carry the joints' Coriolis and centripetal
// terms) against central differences of the generalized-alpha residual in the positions (K),
// velocities (C) and accelerations (M), at a state 0.1 s into the driven motion with nonzero
// multipliers. C includes M_b dc/dW, the velocity derivative of the joints' convective
// accelerations, and K M_b d(J Wdot + c)/dq, their configuration derivative: without them the
// coupling entries of C were 5% off and K half of what it is (Newton then contracted by 3e-4 per
// iteration instead of 3e-7).
TEST(LoopClosure, IterationMatrixOfAMovingFourBarMatchesFiniteDifferences) {
  const FourBar fb;
  const Scene scene =
      BuildScene(ParseScene(fb.Scene("analysis: {type: dynamic, end_time: 0.1, step: 1.0e-3}\n"), "four_bar.yaml"));
  const SystemModel& model = scene.model;
  const DofMap dofs(model);
  DynamicState s = InitialDynamicState(model, InitialState(model), scene.initial_velocity);
  DynamicOptions options;
  options.step = 1e-3;
  options.end_time = 0.1;
  ASSERT_TRUE(SolveDynamic(model, s, options).ok);
  ASSERT_GT(s.config.lambda.norm(), 0.1);
  using namespace dynamic_internal;
  DynamicState base = s;
  BodyWorkspace work;
  Assembly a = AssembleDynamicResidual(model, dofs, base, s.t, work);
  AddDynamicMatrices(model, dofs, base, s.t, work, false, a);
  const Eigen::MatrixXd K(a.K), C(a.C), M(a.M);
  const int n = dofs.n_dofs();
  Eigen::MatrixXd K_fd = Eigen::MatrixXd::Zero(n, n), C_fd = K_fd, M_fd = K_fd;
  auto residual = [&](const DynamicState& state) {
    DynamicState copy = state;
    BodyWorkspace w;
    return AssembleDynamicResidual(model, dofs, copy, s.t, w).residual;
  };
  for (int j : dofs.solved()) {
    const double h = 1e-6;
    const Eigen::VectorXd u = Eigen::VectorXd::Unit(n, j);
    DynamicState plus = s, minus = s;
    ApplyIncrement(model, dofs, h * u, plus.config);
    ApplyIncrement(model, dofs, -h * u, minus.config);
    K_fd.col(j) = -(residual(plus) - residual(minus)) / (2 * h);
    if (dofs.multiplier(j)) continue;  // multipliers have no rates
    plus = s, minus = s;
    plus.W[j] += h, minus.W[j] -= h;
    C_fd.col(j) = -(residual(plus) - residual(minus)) / (2 * h);
    plus = s, minus = s;
    plus.Wdot[j] += h, minus.Wdot[j] -= h;
    M_fd.col(j) = -(residual(plus) - residual(minus)) / (2 * h);
  }
  // Rows and columns of the unknowns solved for.
  auto restrict = [&](const Eigen::MatrixXd& A) {
    Eigen::MatrixXd B = A;
    for (int j = 0; j < n; ++j)
      if (dofs.prescribed(j)) B.row(j).setZero(), B.col(j).setZero();
    return B;
  };
  const double k_error = (restrict(K) - restrict(K_fd)).norm() / restrict(K_fd).norm();
  const double c_error = (restrict(C) - restrict(C_fd)).norm() / restrict(C_fd).norm();
  const double m_error = (restrict(M) - restrict(M_fd)).norm() / restrict(M_fd).norm();
  const int m = dofs.n_multipliers();
  const Eigen::MatrixXd dK = restrict(K) - restrict(K_fd);
  const double g_error = (dK.bottomRows(m).norm() + dK.rightCols(m).norm()) / restrict(K_fd).bottomRows(m).norm();
  std::printf(
      "[ info ] four-bar iteration matrix against central differences: K %.2e (its constraint rows and "
      "columns %.2e), C %.2e, M %.2e (relative)\n",
      k_error, g_error, c_error, m_error);
  EXPECT_LT(k_error, 1e-6);
  EXPECT_LT(g_error, 1e-6);
  EXPECT_LT(c_error, 1e-6);
  EXPECT_LT(m_error, 1e-6);
}

// The four-bar swinging under gravity, no drive, released from rest, with the midpoint scheme,
// 10 s (10 reversals of the crank). Two measures of the energy, the largest over the run,
// relative to the largest kinetic energy or work: (1) T - W_ext with the scheme's own work of the
// external forces; (2) T + V with V = -sum m_b g . x_c,b from the bodies' centres of mass,
// independent of the scheme. The scheme conserves the energy of a chain of rigid bodies exactly
// (node velocities carried by the scheme, discrete gradients of the node Jacobians and of
// gravity, source terms at the mean motion: solver/integrators/midpoint.cpp), so both stay at Newton's
// tolerance; before, the drift was O(h^2): 6.7e-5 at h = 1 ms. `open`: without the joint at D,
// the same links are a triple pendulum (no loop).
struct Swing {
  double drift = 0.0, potential_drift = 0.0, violation = 0.0;
  int reversals = 0;
};
Swing SwingUnderGravity(double h, bool open = false) {
  FourBar fb;
  std::string text = fb.Scene(
      "loads: [{type: gravity, g: [0, -9.81, 0]}]\n"
      "analysis: {type: dynamic, end_time: 10, step: 1.0e-3, integrator: midpoint}\n");
  text = test::Replace(text, ", prescribed: drive}", "}");
  if (open) text = test::Replace(text, "  - {type: revolute, node: D, axis: [0, 0, 1]}\n", "");
  const Scene scene = BuildScene(ParseScene(text, "four_bar.yaml"));
  const SystemModel& model = scene.model;
  const DofMap dofs(model);
  DynamicState s = InitialDynamicState(model, InitialState(model), scene.initial_velocity);
  DynamicOptions options;
  options.step = h;
  options.end_time = 10.0;
  options.integrator = Integrator::kMidpoint;
  Swing run;
  double scale = 0.0, last_rate = 0.0, E0 = 0.0;
  bool first = true;
  const int A = scene.node_index.at("A");
  const DynamicResult r = SolveDynamic(model, s, options, [&](const DynamicStepReport& rep, const DynamicState& st) {
    scale = std::max({scale, rep.kinetic_energy, std::abs(rep.external_work)});
    run.drift = std::max(run.drift, std::abs(rep.kinetic_energy - rep.external_work));
    double V = 0.0;
    for (size_t b = 0; b < model.bodies.size(); ++b) {
      const SuperelementBody& body = model.bodies[b];
      V -= body.mass() * model.gravity.dot(CenterOfMass(
                             body, Evaluate(body, BodyConfigurationOf(model, st.config, int(b)), st.config.frames[b]).q,
                             st.config.frames[b]));
    }
    if (first) E0 = rep.kinetic_energy + V;
    first = false;
    run.potential_drift = std::max(run.potential_drift, std::abs(rep.kinetic_energy + V - E0));
    run.violation = std::max(run.violation, LoopViolation(model, st.config));
    const double rate = st.W[dofs.node_first(A)];
    if (rate * last_rate < 0) ++run.reversals;
    last_rate = rate;
  });
  EXPECT_TRUE(r.ok) << r.message;
  run.drift /= scale;
  run.potential_drift /= scale;
  std::printf(
      "[ info ] %s under gravity, midpoint, h = %.0e s: %d crank reversals, energy drift %.2e (T - W_ext) and "
      "%.2e (T + V) of %.3g J, largest loop violation %.2e m\n",
      open ? "triple pendulum" : "four-bar", h, run.reversals, run.drift, run.potential_drift, scale, run.violation);
  return run;
}

// Energy with gravity and no drive to 1e-6 over 10 periods (midpoint).
TEST(LoopClosure, RigidFourBarUnderGravityKeepsItsEnergyWithTheMidpointScheme) {
  for (const double h : {2e-3, 1e-3}) {
    const Swing run = SwingUnderGravity(h);
    EXPECT_GE(run.reversals, 10);
    EXPECT_LT(run.drift, 1e-6) << "h = " << h;
    EXPECT_LT(run.potential_drift, 1e-6) << "h = " << h;
    EXPECT_LT(run.violation, 1e-12);
  }
}

// The same links without the loop: an open chain of joint coordinates keeps its energy too (it
// drifted 1.9e-3 at h = 2 ms before the node velocities were carried by the scheme).
TEST(LoopClosure, RigidTriplePendulumKeepsItsEnergyWithTheMidpointScheme) {
  const Swing run = SwingUnderGravity(2e-3, true);
  EXPECT_LT(run.drift, 1e-6);
  EXPECT_LT(run.potential_drift, 1e-6);
}

// A parallelogram swing: two rigid links of length l hang from pivots A and D a distance d
// apart and carry a rigid bar BC that translates along a circle. Small oscillations under
// gravity, links of mass m_l each (inertia m_l l^2 / 3 about the pivot), bar m_c:
//   omega^2 = g (m_c + m_l) / (l (m_c + 2 m_l / 3)).
// A `modes` analysis about the static state: the loop's one motion (3 joint angles, 2 kept
// closure equations), its frequency from the joints' and the multipliers' geometric stiffness.
TEST(LoopClosure, ParallelogramSwingHasThePendulumFrequencyOfItsClosedForm) {
  const double d = 0.8, l = 0.5, g = 9.81;
  const Eigen::Vector2d A(0, 0), B(0, -l), C(d, -l), D(d, 0);
  const std::string text = "name: swing\nunits: SI\nbodies:\n" + RigidLink("left", A, B, "A", "B1") +
                           RigidLink("bar", B, C, "B2", "C1") + RigidLink("right", D, C, "D", "C2") +
                           "joints:\n"
                           "  - {type: revolute, node: A, axis: [0, 0, 1]}\n"
                           "  - {type: revolute, node: B2, parent: B1, axis: [0, 0, 1]}\n"
                           "  - {type: revolute, node: C2, parent: C1, axis: [0, 0, 1]}\n"
                           "  - {type: revolute, node: D, axis: [0, 0, 1]}\n"
                           "loads: [{type: gravity, g: [0, -9.81, 0]}]\n"
                           "analysis: {type: modes, about: static, end_time: 1, steps: 1, count: 3}\n";
  const Scene scene = BuildScene(ParseScene(text, "swing.yaml"));
  SystemState state = InitialState(scene.model);
  StaticOptions options;
  options.end_time = 1.0;
  options.steps = 1;
  const StaticResult st = SolveStatic(scene.model, state, options);
  ASSERT_TRUE(st.ok) << st.message;
  const ModalResult modes = LinearizedModes(scene.model, state, 1.0, 3);
  ASSERT_TRUE(modes.ok) << modes.message;
  ASSERT_EQ(modes.frequencies_hz.size(), 1u);  // one degree of freedom
  const double m_l = 2 * l, m_c = 2 * d;
  const double f = std::sqrt(g * (m_c + m_l) / (l * (m_c + 2 * m_l / 3))) / (2 * M_PI);
  std::printf("[ info ] parallelogram swing: %.9f Hz, closed form %.9f Hz; multipliers at rest %.4g N\n",
              modes.frequencies_hz[0], f, state.lambda.norm());
  EXPECT_NEAR(modes.frequencies_hz[0], f, 1e-8 * f);
  // The reactions at rest: by the mirror symmetry each pivot carries half the weight W, straight
  // up, and no moment (every force is in the plane and the pivots turn freely about z). A is a
  // tree joint (its support reaction), D the cut joint (its multipliers): both must be W / 2.
  ASSERT_EQ(scene.model.cut_joints.size(), 1u);
  const DofMap dofs(scene.model);
  SystemState copy = state;
  const SystemForces forces = AssembleStatic(scene.model, dofs, copy, 1.0, false);
  const std::vector<Eigen::Matrix<double, 6, 1>> reactions =
      JointReactions(scene.model, dofs, copy, forces.node_forces);
  const std::vector<Eigen::Matrix<double, 6, 1>> cut = CutJointReactions(scene.model, copy);
  const double W = (2 * m_l + m_c) * g;
  Eigen::Matrix<double, 6, 1> half = Eigen::Matrix<double, 6, 1>::Zero();
  half[1] = W / 2;
  const int nA = scene.node_index.at("A"), nD = scene.node_index.at("D");
  std::printf("[ info ] parallelogram at rest: reaction at A (tree) %.6f N up, at D (cut) %.6f N up, W / 2 = %.6f N\n",
              reactions[size_t(nA)][1], reactions[size_t(nD)][1], W / 2);
  EXPECT_EQ(scene.model.cut_joints[0].joint.child, nD);
  EXPECT_LT((reactions[size_t(nA)] - half).norm(), 1e-9 * W);
  EXPECT_LT((cut[0] - half).norm(), 1e-9 * W);
  EXPECT_LT((reactions[size_t(nD)] - cut[0]).norm(), 1e-15 * W);  // D's reaction is its cut joint's
}

// The rocker driven beyond its range: at the extreme the crank and the coupler fall in line (a
// dead point), the loop cannot close any further, Newton fails, and the run stops (results so
// far kept by the caller) with a message naming the cut joint of the loop.
TEST(LoopClosure, DeadPointStopsTheRunAndNamesTheLoop) {
  FourBar fb;
  std::string text = fb.Scene("analysis: {type: dynamic, end_time: 3, step: 1.0e-3}\n");
  text = test::Replace(text, ", prescribed: drive}", "}");
  text = test::Replace(text, "{type: revolute, node: D, axis: [0, 0, 1]}",
                       "{type: revolute, node: D, axis: [0, 0, 1], prescribed: drive}");
  text = test::Replace(text, "slope: " + Number(fb.omega), "slope: 1");
  const Scene scene = BuildScene(ParseScene(text, "four_bar.yaml"));
  DynamicState s = InitialDynamicState(scene.model, InitialState(scene.model), scene.initial_velocity);
  DynamicOptions options;
  options.step = 1e-3;
  options.end_time = 3.0;
  double t_last = 0.0;
  const DynamicResult r =
      SolveDynamic(scene.model, s, options, [&](const DynamicStepReport& rep, const DynamicState&) { t_last = rep.t; });
  std::printf("[ info ] rocker driven at 1 rad/s: stopped at t = %.4f s: %s\n", t_last, r.message.c_str());
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("revolute joint of node 'C2' on node 'C1': the loop it closes is at or near a singular "
                           "configuration (a dead point"),
            std::string::npos)
      << r.message;
}

// Given velocities that would open the loop (the crank's rate alone, the other joints at rest)
// are made consistent: the nearest in the kinetic-energy norm with G W = 0, the crank's rate
// changed as little as the inertia allows; the rocker then moves as the closed form says,
// dpsi/dtheta from the loop's velocity equations.
TEST(LoopClosure, InitialVelocitiesThatWouldOpenTheLoopAreMadeConsistent) {
  FourBar fb;
  std::string text =
      fb.Scene("initial_velocity: {A: {joint: [3.0]}}\nanalysis: {type: dynamic, end_time: 0.01, step: 1.0e-3}\n");
  text = test::Replace(text, ", prescribed: drive}", "}");
  const Scene scene = BuildScene(ParseScene(text, "four_bar.yaml"));
  const SystemModel& model = scene.model;
  const DofMap dofs(model);
  const DynamicState s = InitialDynamicState(model, InitialState(model), scene.initial_velocity);
  Triplets G;
  AddLoopConstraints(model, dofs, s.config, nullptr, nullptr, nullptr, &G);
  const Eigen::VectorXd GW = ToMatrix(dofs.n_dofs(), G) * s.W;
  const int A = scene.node_index.at("A"), C1 = scene.node_index.at("C1");
  // C's velocity from the closed form: dC/dtheta by central differences of coupler_point.
  const double theta_dot = s.W[dofs.node_first(A)], e = 1e-6;
  const Eigen::Vector2d dC = (fb.C(fb.theta0 + e) - fb.C(fb.theta0 - e)) / (2 * e) * theta_dot;
  const Eigen::Vector2d vC = NodeMotion(s.config, C1, s.W).head<2>();
  std::printf("[ info ] crank rate 3 -> %.6f rad/s; |G W| %.2e; C's velocity %.6f, %.6f (closed form %.6f, %.6f)\n",
              theta_dot, GW.tail(dofs.n_multipliers()).norm(), vC.x(), vC.y(), dC.x(), dC.y());
  EXPECT_LT(GW.tail(dofs.n_multipliers()).norm(), 1e-12);
  EXPECT_LT((vC - dC).norm(), 1e-8 * dC.norm());
  EXPECT_GT(theta_dot, 0.0);
}

// A loop that does not close at t = 0 (the rocker 1 mm too short: its point C misses the
// coupler's): one line naming the joint and the gap.
TEST(LoopClosure, LinksThatDoNotMeetAreAnInputErrorNamingTheJointAndTheGap) {
  FourBar fb;
  const Eigen::Vector2d D(fb.d, 0), C = fb.C(fb.theta0), C_short = D + (C - D) * (1 - 0.001 / fb.c);
  std::string text = fb.Scene("analysis: {type: dynamic, end_time: 0.01, step: 1.0e-3}\n");
  text = test::Replace(text, RigidLink("rocker", D, C, "D", "C2"), RigidLink("rocker", D, C_short, "D", "C2"));
  const std::string message = test::ThrownMessage([&] { BuildScene(ParseScene(text, "four_bar.yaml")); });
  EXPECT_NE(message.find("revolute joint between nodes 'C2' and 'C1': the nodes are 0.001 apart at t = 0"),
            std::string::npos)
      << message;
}

TEST(LoopClosure, PrescribedJointThatClosesALoopIsAnInputError) {
  FourBar fb;
  std::string text = fb.Scene("analysis: {type: dynamic, end_time: 1, step: 1.0e-3}\n");
  // Two drives on one rigid link (the rocker at C and at D): the second cannot be a tree joint.
  text = test::Replace(text, "{type: revolute, node: D, axis: [0, 0, 1]}",
                       "{type: revolute, node: D, axis: [0, 0, 1], prescribed: drive}");
  text = test::Replace(text, "{type: revolute, node: C2, parent: C1, axis: [0, 0, 1]}",
                       "{type: revolute, node: C2, parent: C1, axis: [0, 0, 1], prescribed: drive}");
  const std::string message = test::ThrownMessage([&] { BuildScene(ParseScene(text, "four_bar.yaml")); });
  EXPECT_NE(message.find("is prescribed but closes a loop"), std::string::npos) << message;
  EXPECT_NE(message.find("node 'D'"), std::string::npos) << message;
}

}  // namespace
}  // namespace femb
