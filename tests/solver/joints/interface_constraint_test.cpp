// Thesis 8.2 case 4 in femb-solve: a rod reduced on four free-free bending shapes,
// which cannot stretch or twist it, carries the interface constraint C q_int = 0 that femb-solve
// enforces with Lagrange multipliers. Checked: the constraint's Jacobian and the multipliers'
// geometric stiffness in the static tangent against central finite differences (a chain of two
// such rods in a general pose); an axial force and a torque neither stretch nor twist the rod
// while a Craig-Bampton rod of the same beam stretches by P L / (E A) (closed form); a small
// transverse load gives the reduced model's own linear answer (the same matrices solved with
// the constraint by hand), stiffer than beam theory, and so do the linearized modes; a swinging
// pendulum of two such rods keeps its constraint closed and its energy with the midpoint scheme.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <random>

#include "solver/analysis/dynamic_analysis.h"
#include "solver/analysis/dynamic_step.h"
#include "solver/analysis/modal_analysis.h"
#include "solver/analysis/static_analysis.h"
#include "solver/assembly/system.h"
#include "solver/rotation.h"
#include "test_util.h"

namespace femb {
namespace {

constexpr double kL = 0.5, kE = 2.0e9, kD = 0.02;

// The rod on its four lowest free-free bending shapes (test::BendingShapesRod), or its
// Craig-Bampton reduction.
Superelement Rod(bool bending_only) {
  if (bending_only) return test::BendingShapesRod(kL);
  return test::Reduce(test::StraightBeamYaml(kL, 20, "{shape: circle, diameter: 0.02}",
                                             "{E: 2.0e9, nu: 0.3, rho: 7800}", "[{name: A}, {name: B}]") +
                      "reduction: {internal_modes: 4, floating_frame: mean_axes}\n");
}

// Two rods in a chain along x: n0 on a revolute joint to ground about z, n2 hinged to n1 by a
// revolute joint about (0.36, 0.48, 0.8); gravity -y.
SystemModel Chain(const Superelement& se, const SuperelementOptions& options = {}) {
  SystemModel model;
  AddNode(model, "n0", Eigen::Vector3d::Zero());
  AddNode(model, "n1", Eigen::Vector3d(kL, 0, 0));
  AddNode(model, "n2", Eigen::Vector3d(kL, 0, 0));
  AddNode(model, "n3", Eigen::Vector3d(2 * kL, 0, 0));
  model.bodies.emplace_back(se, options, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  model.body_nodes.push_back({0, 1});
  model.bodies.emplace_back(se, options, Eigen::Matrix3d::Identity(), Eigen::Vector3d(kL, 0, 0));
  model.body_nodes.push_back({2, 3});
  RevoluteToGround(model, 0, Eigen::Vector3d::UnitZ());
  model.joints.push_back(MakeNodeJoint(JointType::kRevolute, 2, 1, Eigen::Vector3d(0, 0, 1), model.node_x0[1],
                                       model.node_R0[1], model.node_x0[2], model.node_R0[2]));
  model.gravity = Eigen::Vector3d(0, -9.81, 0);
  model.Number();
  return model;
}

TEST(InterfaceConstraint, StaticTangentMatchesFiniteDifferences) {
  const Superelement se = Rod(true);
  SystemModel model = Chain(se);
  // A hinge about a tilted axis and a load with a moment, so that every block is exercised.
  model.joints[1] =  // joint 0 is n0's revolute to the ground
      MakeNodeJoint(JointType::kRevolute, 2, 1, Eigen::Vector3d(0.36, 0.48, 0.8), model.node_x0[1], model.node_R0[1],
                    model.node_x0[2], model.node_R0[2]);
  NodeLoad load;
  load.node = 3;
  load.force = Eigen::Vector3d(10, -20, 15);
  load.moment = Eigen::Vector3d(1, 2, -1);
  model.loads.push_back(load);
  const DofMap dofs(model);
  ASSERT_EQ(dofs.n_multipliers(), 4);
  ASSERT_EQ(dofs.body_multiplier_first(1) - dofs.body_multiplier_first(0), 2);
  SystemState state = InitialState(model);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::VectorXd shift(dofs.n_dofs());
  for (int i = 0; i < shift.size(); ++i) shift[i] = dofs.multiplier(i) ? 50.0 * u(rng) : 0.05 * u(rng);
  ApplyIncrement(model, dofs, shift, state);
  const SystemForces f0 = AssembleStatic(model, dofs, state, 1.0, true);
  ASSERT_TRUE(f0.ok) << f0.message;
  const Eigen::MatrixXd K_fd = test::StaticTangentByDifferences(model, dofs, state, 1.0);
  const Eigen::MatrixXd K(f0.tangent);
  const int m = dofs.n_multipliers(), c = dofs.first_multiplier();
  const double error = (K - K_fd).norm() / K_fd.norm();
  const double g_error =
      (K.bottomLeftCorner(m, c) - K_fd.bottomLeftCorner(m, c)).norm() / K_fd.bottomLeftCorner(m, c).norm();
  // The multipliers' share alone: the tangent with and without them.
  SystemState no_lambda = state;
  no_lambda.lambda.setZero();
  const Eigen::MatrixXd K0(AssembleStatic(model, dofs, no_lambda, 1.0, true).tangent);
  const Eigen::MatrixXd K0_fd = test::StaticTangentByDifferences(model, dofs, no_lambda, 1.0);
  const double h_error =
      ((K - K0) - (K_fd - K0_fd)).topLeftCorner(c, c).norm() / (K_fd - K0_fd).topLeftCorner(c, c).norm();
  std::printf(
      "[ info ] %d coordinates, %d multipliers: tangent error %.2e, constraint rows %.2e, "
      "multipliers' "
      "geometric stiffness %.2e (its size %.2e of the tangent's)\n",
      c, m, error, g_error, h_error, (K_fd - K0_fd).topLeftCorner(c, c).norm() / K_fd.norm());
  EXPECT_LT(error, 1e-6);
  EXPECT_LT(g_error, 1e-6);
  EXPECT_LT(h_error, 1e-5);
}

// One rod clamped at n0 with a load on n1: returns n1's displacement and rotation vector.
Eigen::Matrix<double, 6, 1> ClampedTip(const Superelement& se, const Eigen::Vector3d& force,
                                       const Eigen::Vector3d& moment) {
  SystemModel model = test::ClampedOneBodyModel(se, kL, force);
  model.loads[0].moment = moment;
  SystemState state = InitialState(model);
  StaticOptions options;
  options.steps = 1;
  const StaticResult r = SolveStatic(model, state, options);
  EXPECT_TRUE(r.ok) << r.message;
  Eigen::Matrix<double, 6, 1> out;
  out << state.x[1] - model.node_x0[1], LogSO3(state.R[1] * model.node_R0[1].transpose());
  return out;
}

TEST(InterfaceConstraint, AxialForceAndTorqueNeitherStretchNorTwistTheRod) {
  const Superelement bending = Rod(true), cb = Rod(false);
  const double A = M_PI * kD * kD / 4, P = 2.0e4, T = 20.0;
  const Eigen::Matrix<double, 6, 1> stiff = ClampedTip(bending, Eigen::Vector3d(P, 0, 0), Eigen::Vector3d(T, 0, 0));
  const Eigen::Matrix<double, 6, 1> elastic = ClampedTip(cb, Eigen::Vector3d(P, 0, 0), Eigen::Vector3d(T, 0, 0));
  const double stretch = P * kL / (kE * A);
  std::printf(
      "[ info ] axial %.0f N, torque %.0f N m: Craig-Bampton stretch %.6e m (P L / E A %.6e), "
      "twist %.4e rad; "
      "bending shapes: stretch %.2e m, twist %.2e rad\n",
      P, T, elastic[0], stretch, elastic[3], stiff[0], stiff[3]);
  EXPECT_NEAR(elastic[0], stretch, 1e-6 * stretch);
  EXPECT_GT(std::abs(elastic[3]), 1e-3);
  EXPECT_LT(std::abs(stiff[0]), 1e-9 * stretch);
  EXPECT_LT(std::abs(stiff[3]), 1e-9 * std::abs(elastic[3]));
  EXPECT_LT(stiff.norm(), 1e-9 * stretch);
}

TEST(InterfaceConstraint, SmallTransverseLoadGivesTheReducedModelsLinearAnswer) {
  const Superelement se = Rod(true);
  const double F = 0.01, I = M_PI * std::pow(kD, 4) / 64;
  const Eigen::Matrix<double, 6, 1> tip = ClampedTip(se, Eigen::Vector3d(0, F, 0), Eigen::Vector3d::Zero());
  // The same reduced model solved by hand: node A held, B's six coordinates and the constraint's
  // columns of B (C's columns of A multiply zeros), [K_BB C_B^T; C_B 0] [q; mu] = [f; 0].
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(8, 8);
  S.topLeftCorner(6, 6) = se.K.block(6, 6, 6, 6);
  S.block(6, 0, 2, 6) = se.interface_constraint.rightCols(6);
  S.block(0, 6, 6, 2) = se.interface_constraint.rightCols(6).transpose();
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(8);
  rhs[1] = F;
  const Eigen::VectorXd q = S.fullPivLu().solve(rhs);
  const double beam_theory = F * std::pow(kL, 3) / (3 * kE * I);
  std::printf(
      "[ info ] tip deflection %.9e m; reduced model by hand %.9e m (%.2e); beam theory F L^3 / "
      "3EI %.6e m "
      "(%+.3f%%)\n",
      tip[1], q[1], tip[1] / q[1] - 1, beam_theory, 100 * (tip[1] / beam_theory - 1));
  EXPECT_NEAR(tip[1], q[1], 1e-6 * std::abs(q[1]));
  EXPECT_NEAR(tip[5], q[5], 1e-6 * std::abs(q[5]));
  // Rayleigh-Ritz: stiffer than the beam. By much (-38%): a free-free shape has no curvature at
  // the rod's ends, so the clamped root's bending moment is not in the basis (what residual
  // attachment modes would add).
  EXPECT_LT(tip[1], beam_theory * (1 + 1e-9));
}

// Linearized modes of the clamped bending-only rod (null-space projection of the multipliers)
// against the reduced model's own constrained eigenproblem: B's coordinates on the null space of
// C_B, K_BB and M_BB projected (1e-8).
TEST(InterfaceConstraint, LinearizedModesAreThoseOfTheConstrainedReducedModel) {
  const Superelement se = Rod(true);
  SystemModel model = test::ClampedOneBodyModel(se, kL, Eigen::Vector3d::Zero());
  SystemState state = InitialState(model);
  const ModalResult modes = LinearizedModes(model, state, 0.0);
  ASSERT_TRUE(modes.ok) << modes.message;
  Eigen::FullPivLU<Eigen::MatrixXd> lu(se.interface_constraint.rightCols(6));
  const Eigen::MatrixXd N = lu.kernel();
  ASSERT_EQ(N.cols(), 4);
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(
      N.transpose() * se.K.block(6, 6, 6, 6) * N, N.transpose() * se.M.block(6, 6, 6, 6) * N, Eigen::EigenvaluesOnly);
  ASSERT_EQ(modes.frequencies_hz.size(), 4);
  double worst = 0.0;
  for (int j = 0; j < 4; ++j) {
    const double f = std::sqrt(eig.eigenvalues()[j]) / (2 * M_PI);
    worst = std::max(worst, std::abs(modes.frequencies_hz[j] / f - 1));
  }
  std::printf(
      "[ info ] clamped bending-only rod: %d modes (%.2f, %.2f, %.2f, %.2f Hz), within %.2e of the "
      "constrained "
      "reduced model's\n",
      int(modes.frequencies_hz.size()), modes.frequencies_hz[0], modes.frequencies_hz[1], modes.frequencies_hz[2],
      modes.frequencies_hz[3], worst);
  EXPECT_LT(worst, 1e-8);
}

// Released horizontal, the two bending-only rods swing for 1 s. The constraint stays closed to
// the Newton tolerance and the midpoint scheme keeps the energy (kinetic + elastic - work of
// gravity) as for Craig-Bampton rods (the constraint forces do no work); the Radau IIA scheme
// (each stage with its own multipliers) keeps it to its fifth-order error. The bodies' inertia:
// the midpoint scheme's corotational one, the exact one otherwise (the general basis' file has
// the inertia invariants).
TEST(InterfaceConstraint, SwingingChainKeepsItsConstraintAndItsEnergy) {
  const Superelement se = Rod(true);
  ASSERT_FALSE(se.inertia_gamma.empty());
  for (const Integrator integrator : {Integrator::kMidpoint, Integrator::kGeneralizedAlpha, Integrator::kRadau}) {
    SuperelementOptions body_options;
    body_options.exact_inertia = integrator != Integrator::kMidpoint;
    const SystemModel model = Chain(se, body_options);
    const DofMap dofs(model);
    DynamicState s = InitialDynamicState(model, InitialState(model), Eigen::VectorXd::Zero(dofs.n_dofs()));
    const DynamicStepReport r0 = Measure(model, s);
    DynamicOptions options;
    options.step = 1e-3;
    options.end_time = 1.0;
    options.rho_inf = 1.0;
    options.integrator = integrator;
    const double scale = 2 * se.mass_properties.mass * 9.81 * kL;
    double drift = 0.0, gap = 0.0, min_y = 0.0;
    const DynamicResult result =
        SolveDynamic(model, s, options, [&](const DynamicStepReport& r, const DynamicState& st) {
          const double E = r.kinetic_energy + r.elastic_energy - r.external_work;
          drift = std::max(drift, std::abs(E - (r0.kinetic_energy + r0.elastic_energy)) / scale);
          gap = std::max(gap, LoopViolation(model, st.config));
          min_y = std::min(min_y, st.config.x[3].y());
        });
    ASSERT_TRUE(result.ok) << result.message;
    std::printf(
        "[ info ] %s, h = 1 ms, 1 s: energy drift %.2e of 2 m g L, constraint gap %.2e m, lowest "
        "tip %.3f m\n",
        integrator == Integrator::kMidpoint           ? "midpoint"
        : integrator == Integrator::kGeneralizedAlpha ? "generalized-alpha"
                                                      : "Radau IIA",
        drift, gap, min_y);
    EXPECT_LT(min_y, -0.8);  // it swung
    EXPECT_LT(gap, 1e-9 * kL);
    // Measured: midpoint 1.5e-6, generalized-alpha 2.4e-5, Radau IIA 2.0e-9 (fifth order).
    EXPECT_LT(drift, integrator == Integrator::kMidpoint ? 1e-5 : integrator == Integrator::kRadau ? 1e-7 : 1e-4);
  }
}

}  // namespace
}  // namespace femb
