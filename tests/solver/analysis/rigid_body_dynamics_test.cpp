// A superelement with one interface node and no internal modes is a rigid body (its local
// coordinates are identically zero). Against rigid-body invariants and closed forms:
// torque-free motion conserves energy and angular momentum (generalized-alpha, rho_inf = 1:
// no secular drift, error O(h^2)), the intermediate-axis flip, and the steady precession rate of
// a heavy symmetric top on a spherical joint.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>

#include "solver/analysis/dynamic_analysis.h"
#include "solver/rotation.h"
#include "test_util.h"

namespace femb {
namespace {

// Three unequal arms from the centre C: principal moments all different. The interface node is
// C (at the centre of mass) or the end A of the longest arm.
Superelement Jack(const std::string& node = "C") {
  return test::Reduce(
      "name: jack\ntype: beam\nmaterial: {E: 2.0e11, nu: 0.3, rho: 7800}\n"
      "section: {shape: circle, diameter: 0.01}\n"
      "beam:\n  points: {C: [0, 0, 0], A: [0.3, 0, 0], B: [0, 0.2, 0], D: [0, 0, 0.1], E: [-0.3, 0, 0], F: [0, -0.2, "
      "0], G: [0, 0, -0.1]}\n"
      "  segments: [{from: C, to: A, elements: 4}, {from: C, to: B, elements: 4}, {from: C, to: D, elements: 2},\n"
      "             {from: C, to: E, elements: 4}, {from: C, to: F, elements: 4}, {from: C, to: G, elements: 2}]\n"
      "interfaces: [{name: " +
      node + "}]\nreduction: {internal_modes: 0, floating_frame: 'interface:" + node + "'}\n");
}

struct FlightErrors {
  double energy_error = 0, momentum_error = 0;
  double momentum_error_first_half = 0, momentum_error_second_half = 0;
  double min_intermediate = 1;  // min of Omega_2 / |Omega| (body frame, intermediate axis)
  long steps = 0;
};

// Free flight from spin omega0 (spatial) about the centre of mass, n_steps of size h (with a
// step_tolerance, error-controlled steps from h over the same time).
FlightErrors FreeFlight(const Superelement& se, const Eigen::Vector3d& omega0, double h, int n_steps, double rho = 1.0,
                        const Eigen::Vector3d& intermediate_axis = Eigen::Vector3d::Zero(),
                        Integrator integrator = Integrator::kGeneralizedAlpha, double tolerance = 1e-9,
                        double step_tolerance = 0.0) {
  SystemModel model;
  AddNode(model, se.interfaces[0].name, se.interfaces[0].position);
  model.bodies.emplace_back(se, SuperelementOptions{});
  model.body_nodes.push_back({0});
  const Eigen::Vector3d c = se.mass_properties.center_of_mass;
  Eigen::VectorXd W(6);
  W << omega0.cross(se.interfaces[0].position - c), omega0;
  model.Number();
  DynamicState s = InitialDynamicState(model, InitialState(model), W);
  const DynamicStepReport r0 = Measure(model, s);
  DynamicOptions options;
  options.step = h;
  options.end_time = h * n_steps;
  options.rho_inf = rho;
  options.integrator = integrator;
  options.tolerance = tolerance;
  options.adaptive = step_tolerance > 0;
  options.step_tolerance = step_tolerance;
  FlightErrors run;
  const DynamicResult result = SolveDynamic(model, s, options, [&](const DynamicStepReport& r, const DynamicState& st) {
    run.energy_error = std::max(run.energy_error, std::abs(r.kinetic_energy - r0.kinetic_energy) / r0.kinetic_energy);
    const double dH = (r.angular_momentum - r0.angular_momentum).norm() / r0.angular_momentum.norm();
    run.momentum_error = std::max(run.momentum_error, dH);
    double& half = r.t < 0.5 * options.end_time ? run.momentum_error_first_half : run.momentum_error_second_half;
    half = std::max(half, dH);
    if (intermediate_axis.squaredNorm() > 0) {
      const Eigen::Vector3d Omega = st.config.R[0].transpose() * st.W.tail<3>();
      run.min_intermediate = std::min(run.min_intermediate, Omega.dot(intermediate_axis) / Omega.norm());
    }
  });
  EXPECT_TRUE(result.ok) << result.message;
  run.steps = result.steps;
  return run;
}

TEST(RigidBodyDynamics, TorqueFreeMotionConservesEnergyAndMomentumAtSecondOrder) {
  const Superelement se = Jack();
  const Eigen::Vector3d omega0(1.0, 2.0, 3.0);
  const double period = 2 * M_PI / omega0.norm();
  const FlightErrors coarse = FreeFlight(se, omega0, period / 100, 1000);
  const FlightErrors fine = FreeFlight(se, omega0, period / 200, 2000);
  std::printf("[ info ] 100 steps/rev: energy %.3e momentum %.3e; 200 steps/rev: energy %.3e momentum %.3e\n",
              coarse.energy_error, coarse.momentum_error, fine.energy_error, fine.momentum_error);
  // Generalized-alpha is not an energy-momentum scheme: the spatial angular momentum vector
  // oscillates with amplitude ~ (omega h)^2 / 2, bounded: measured 1.84e-3 at 100 steps per
  // revolution with the step's rotation from its total increment (1.35e-3 with Newton's
  // corrections composed, which makes the state depend on Newton's path), and the energy error
  // 3.0e-5 at 200 (4.7e-5 composed).
  // (The target 1e-4 at 100 steps/rev needs a conserving scheme; see the notes.)
  const double omega_h = omega0.norm() * period / 100;
  EXPECT_LT(coarse.momentum_error, omega_h * omega_h / 2);
  // Energy: below 1e-4 from 200 steps per revolution on (3e-4 at 100, printed above).
  EXPECT_LT(fine.energy_error, 1e-4);
  // No secular drift: the second half of the run is no worse than the first (within 20%).
  EXPECT_LT(coarse.momentum_error_second_half, 1.2 * coarse.momentum_error_first_half);
  // Second order: halving the step divides the error by about 4.
  EXPECT_GT(coarse.momentum_error / fine.momentum_error, 3.5);
  EXPECT_LT(coarse.momentum_error / fine.momentum_error, 4.5);
  EXPECT_GT(coarse.energy_error / fine.energy_error, 3.5);
}

// The three-stage Radau IIA integrator (solver/integrators/radau.cpp): not an energy-momentum
// scheme, but of fifth order, so the invariants hold to its error, which halving the step divides
// by about 32 (a free node: the stages' rotations through the inverse left Jacobian).
TEST(RigidBodyDynamics, RadauKeepsTheInvariantsToFifthOrder) {
  const Superelement se = Jack();
  const Eigen::Vector3d omega0(1.0, 2.0, 3.0);
  const double period = 2 * M_PI / omega0.norm();
  const Eigen::Vector3d none = Eigen::Vector3d::Zero();
  // Ten revolutions at 20 and 40 steps per revolution (omega h = 0.31 and 0.16).
  const FlightErrors coarse = FreeFlight(se, omega0, period / 20, 200, 1.0, none, Integrator::kRadau, 1e-12);
  const FlightErrors fine = FreeFlight(se, omega0, period / 40, 400, 1.0, none, Integrator::kRadau, 1e-12);
  std::printf("[ info ] Radau IIA: 20 steps/rev: energy %.3e momentum %.3e; 40 steps/rev: energy %.3e momentum %.3e\n",
              coarse.energy_error, coarse.momentum_error, fine.energy_error, fine.momentum_error);
  // Generalized-alpha needs 100 steps per revolution for a momentum error of 1.8e-3 (above);
  // this scheme keeps both invariants below 1e-4 at 20 (measured 1.1e-5 and 2.5e-5).
  EXPECT_LT(coarse.momentum_error, 1e-4);
  EXPECT_LT(coarse.energy_error, 1e-4);
  // Fifth order: measured 31.7x for both; at least 2^4.3 = 20.
  EXPECT_GT(coarse.momentum_error / fine.momentum_error, 20.0);
  EXPECT_GT(coarse.energy_error / fine.energy_error, 20.0);
  // The slope of the error against the step from 20 to 80 steps per revolution (the finest at
  // 1e-8 and 2.5e-8, far above Newton's tolerance): measured 4.98 and 5.00 for the energy, 4.99
  // and 5.00 for the momentum.
  const FlightErrors finest = FreeFlight(se, omega0, period / 80, 800, 1.0, none, Integrator::kRadau, 1e-12);
  const double slopes[4] = {
      std::log2(coarse.energy_error / fine.energy_error), std::log2(fine.energy_error / finest.energy_error),
      std::log2(coarse.momentum_error / fine.momentum_error), std::log2(fine.momentum_error / finest.momentum_error)};
  std::printf(
      "[ info ] Radau IIA: 80 steps/rev: energy %.3e momentum %.3e; slopes: energy %.2f, %.2f; momentum %.2f, "
      "%.2f\n",
      finest.energy_error, finest.momentum_error, slopes[0], slopes[1], slopes[2], slopes[3]);
  for (double slope : slopes) EXPECT_NEAR(slope, 5.0, 0.1);
}

// Radau IIA under error control (its own estimate, RadauLocalError): the same ten revolutions
// from a first step of a hundredth of a revolution. The invariants' errors fall with
// step_tolerance, and the steps grow about as the fifth root of it.
TEST(RigidBodyDynamics, RadauErrorControlledStepsKeepTheInvariantsToTheTolerance) {
  const Superelement se = Jack();
  const Eigen::Vector3d omega0(1.0, 2.0, 3.0);
  const double period = 2 * M_PI / omega0.norm();
  const Eigen::Vector3d none = Eigen::Vector3d::Zero();
  FlightErrors runs[3];
  const double tolerances[3] = {1e-3, 1e-5, 1e-7};
  for (int k = 0; k < 3; ++k) {
    runs[k] = FreeFlight(se, omega0, period / 100, 1000, 1.0, none, Integrator::kRadau, 1e-12, tolerances[k]);
    std::printf("[ info ] Radau IIA, step_tolerance %g: %ld steps over ten revolutions, energy %.3e momentum %.3e\n",
                tolerances[k], runs[k].steps, runs[k].energy_error, runs[k].momentum_error);
  }
  for (int k = 1; k < 3; ++k) {
    EXPECT_LT(runs[k].energy_error, runs[k - 1].energy_error / 10);
    EXPECT_LT(runs[k].momentum_error, runs[k - 1].momentum_error / 10);
    EXPECT_GT(runs[k].steps, runs[k - 1].steps);
  }
}

// The momentum-conserving midpoint scheme is Simo & Wong's energy-momentum scheme for a rigid
// body: energy and angular momentum are invariants of the discrete map, kept to the Newton
// tolerance whatever the step. Also with the node off the centre of mass (the body's momentum
// then couples translation and rotation).
TEST(RigidBodyDynamics, MidpointSchemeConservesEnergyAndMomentumExactly) {
  for (const std::string node : {"C", "A"}) {
    const Superelement se = Jack(node);
    const Eigen::Vector3d omega0(1.0, 2.0, 3.0);
    const double period = 2 * M_PI / omega0.norm();
    const Eigen::Vector3d none = Eigen::Vector3d::Zero();
    // Default Newton tolerance (1e-9 relative residual): the bound is 1e-4 at 100 steps
    // per revolution over 1000 steps; the errors are those of the Newton iterations, far below.
    const FlightErrors coarse = FreeFlight(se, omega0, period / 100, 1000, 1.0, none, Integrator::kMidpoint);
    const FlightErrors fine = FreeFlight(se, omega0, period / 200, 2000, 1.0, none, Integrator::kMidpoint);
    // Tight tolerance: round-off.
    const FlightErrors tight = FreeFlight(se, omega0, period / 100, 1000, 1.0, none, Integrator::kMidpoint, 1e-12);
    std::printf(
        "[ info ] midpoint, node %s: 100 steps/rev: energy %.3e momentum %.3e; 200 steps/rev: energy %.3e "
        "momentum %.3e; 100 steps/rev, Newton to 1e-12: energy %.3e momentum %.3e\n",
        node.c_str(), coarse.energy_error, coarse.momentum_error, fine.energy_error, fine.momentum_error,
        tight.energy_error, tight.momentum_error);
    for (const FlightErrors& run : {coarse, fine}) {
      EXPECT_LT(run.energy_error, 1e-6);
      EXPECT_LT(run.momentum_error, 1e-6);
    }
    EXPECT_LT(tight.energy_error, 1e-11);
    EXPECT_LT(tight.momentum_error, 1e-11);
  }
}

TEST(RigidBodyDynamics, SpinAboutTheIntermediateAxisFlips) {
  const Superelement se = Jack();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> principal(se.mass_properties.inertia_com);
  const Eigen::Vector3d e1 = principal.eigenvectors().col(0), e2 = principal.eigenvectors().col(1);
  const double rate = 5.0;
  const Eigen::Vector3d omega0 = rate * (e2 + 1e-3 * e1);
  const double period = 2 * M_PI / rate;
  for (Integrator integrator : {Integrator::kGeneralizedAlpha, Integrator::kMidpoint}) {
    const FlightErrors run = FreeFlight(se, omega0, period / 200, 4000, 1.0, e2, integrator);
    // Initially Omega . e2 / |Omega| = 1; the Dzhanibekov flip takes it to about -1.
    EXPECT_LT(run.min_intermediate, -0.9);
    EXPECT_LT(run.energy_error, 1e-3);
  }
}

// Heavy symmetric top: an axis from the pivot P and a 4-fold cross at its top end.
Superelement Top() {
  return test::Reduce(
      "name: top\ntype: beam\nmaterial: {E: 2.0e11, nu: 0.3, rho: 7800}\n"
      "section: {shape: circle, diameter: 0.008}\n"
      "beam:\n  points: {P: [0, 0, 0], H: [0, 0, 0.1], X1: [0.08, 0, 0.1], X2: [-0.08, 0, 0.1],\n"
      "           Y1: [0, 0.08, 0.1], Y2: [0, -0.08, 0.1]}\n"
      "  segments: [{from: P, to: H, elements: 4}, {from: H, to: X1, elements: 3}, {from: H, to: X2, elements: 3},\n"
      "             {from: H, to: Y1, elements: 3}, {from: H, to: Y2, elements: 3}]\n"
      "interfaces: [{name: P}]\nreduction: {internal_modes: 0, floating_frame: 'interface:P'}\n");
}

TEST(RigidBodyDynamics, HeavySymmetricTopPrecessesAtTheAnalyticRate) {
  const Superelement se = Top();
  const double m = se.mass_properties.mass, g = 9.81;
  const Eigen::Vector3d c = se.mass_properties.center_of_mass;
  const double l = c.z();
  const Eigen::Matrix3d J_pivot =
      se.mass_properties.inertia_com + m * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
  const double I1 = J_pivot(0, 0), I3 = J_pivot(2, 2);
  ASSERT_NEAR(J_pivot(0, 0), J_pivot(1, 1), 1e-9 * I1);
  // Tilt the axis by theta about x; steady precession Omega_p about the vertical with spin
  // component omega3 along the axis: m g l = Omega_p (I3 omega3 - I1 Omega_p cos theta) (slow root).
  const double theta = 0.4, omega3 = 150.0;
  const double A = I1 * std::cos(theta), Bq = -I3 * omega3, Cq = m * g * l;
  const double Omega_p = (-Bq - std::sqrt(Bq * Bq - 4 * A * Cq)) / (2 * A);
  const Eigen::Matrix3d R0 = ExpSO3(Eigen::Vector3d(theta, 0, 0));
  const Eigen::Vector3d axis = R0 * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  // omega = Omega_p z + psidot axis with omega . axis = omega3.
  const double psidot = omega3 - Omega_p * std::cos(theta);
  const Eigen::Vector3d omega = Omega_p * z + psidot * axis;

  auto precession = [&](int steps_per_precession, double* nutation, Integrator integrator) {
    SystemModel model;
    AddNode(model, "P", Eigen::Vector3d::Zero(), R0);
    Pin(model, 0);
    model.bodies.emplace_back(se, SuperelementOptions{}, R0, Eigen::Vector3d::Zero());
    model.body_nodes.push_back({0});
    model.gravity = Eigen::Vector3d(0, 0, -g);
    Eigen::VectorXd W(3);
    W << omega;
    model.Number();
    DynamicState s = InitialDynamicState(model, InitialState(model), W);
    DynamicOptions options;
    const double precession_period = 2 * M_PI / Omega_p;
    options.step = precession_period / steps_per_precession;
    options.end_time = 0.25 * precession_period;
    options.rho_inf = 1.0;
    options.integrator = integrator;
    double max_nutation = 0;
    EXPECT_TRUE(SolveDynamic(model, s, options, [&](const DynamicStepReport&, const DynamicState& st) {
                  const Eigen::Vector3d a = st.config.R[0] * Eigen::Vector3d::UnitZ();
                  max_nutation = std::max(max_nutation, std::abs(std::acos(a.z()) - theta));
                }).ok);
    const Eigen::Vector3d a = s.config.R[0] * Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d a0 = axis;
    const double azimuth = std::atan2(a.y(), a.x()) - std::atan2(a0.y(), a0.x());
    *nutation = max_nutation;
    return azimuth / s.t;
  };
  for (Integrator integrator : {Integrator::kGeneralizedAlpha, Integrator::kMidpoint}) {
    double nutation_coarse, nutation_fine;
    const double coarse = precession(2000, &nutation_coarse, integrator);
    const double fine = precession(8000, &nutation_fine, integrator);
    std::printf(
        "[ info ] precession (%s): analytic %.6f rad/s, femb %.6f (55 steps per spin turn), %.6f (220); "
        "nutation %.2e, %.2e rad\n",
        integrator == Integrator::kMidpoint ? "midpoint" : "generalized-alpha", Omega_p, coarse, fine, nutation_coarse,
        nutation_fine);
    // Time discretization error, second order in the spin step: within 0.05% at 220 steps per
    // spin revolution and shrinking ~16x from 55 steps.
    EXPECT_NEAR(fine, Omega_p, 5e-4 * Omega_p);
    EXPECT_GT(std::abs(coarse - Omega_p) / std::abs(fine - Omega_p), 8.0);
    EXPECT_LT(nutation_fine, 1e-4);
  }
}

}  // namespace
}  // namespace femb
