// Flexible superelements in motion: a clamped body rings at its reduced model's first
// eigenfrequency, and a free spinning flexible body conserves energy and momentum.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <optional>

#include "solver/analysis/dynamic_analysis.h"
#include "test_util.h"

namespace femb {
namespace {

Superelement Tube(int modes) {
  return test::Reduce(
      "name: tube\ntype: beam\nmaterial: {E: 70.0e9, nu: 0.3, rho: 2700}\n"
      "section: {shape: tube, outer_radius: 0.01, wall: 0.001}\n"
      "beam:\n  points: {A: [0, 0, 0], B: [1, 0, 0]}\n  segments: [{from: A, to: B, elements: 10}]\n"
      "interfaces: [{name: A}, {name: B}]\nreduction: {internal_modes: " +
      std::to_string(modes) + ", geometric_stiffening: false}\n");
}

// One tube body on nodes A (x = 0, clamped) and B (x = 1).
SystemModel ClampedTube(const Superelement& se, const SuperelementOptions& options = {}) {
  SystemModel model;
  AddNode(model, "A", Eigen::Vector3d::Zero());
  AddNode(model, "B", Eigen::Vector3d(1, 0, 0));
  Clamp(model, 0);
  model.bodies.emplace_back(se, options);
  model.body_nodes.push_back({0, 1});
  model.Number();
  return model;
}

TEST(FlexibleDynamics, ClampedBodyRingsAtTheReducedModelsFirstFrequency) {
  const Superelement se = Tube(4);
  // Reference: eigenvalues of the reduced model with interface A clamped.
  const int n = se.n_reduced_dofs();
  const Eigen::MatrixXd K = se.K.bottomRightCorner(n - 6, n - 6), M = se.M.bottomRightCorner(n - 6, n - 6);
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(K, M);
  const double f1 = std::sqrt(eig.eigenvalues()[0]) / (2 * M_PI);

  SystemModel model = ClampedTube(se);
  // A small vertical tip impulse: 1 N for 1 ms.
  NodeLoad pulse;
  pulse.node = 1;
  pulse.force = Eigen::Vector3d(0, 1.0, 0);
  pulse.scale = [](double t) { return t < 1e-3 ? 1.0 : 0.0; };
  model.loads.push_back(pulse);
  DynamicState s = InitialDynamicState(model, InitialState(model), Eigen::VectorXd::Zero(DofMap(model).n_dofs()));
  DynamicOptions options;
  options.step = 1.0 / (f1 * 200);
  options.end_time = 10.0 / f1;
  options.rho_inf = 1.0;
  // Tip history, then up-crossings with hysteresis: the second mode (6.3 f1) rides on the first
  // and would add spurious crossings near zero.
  std::vector<double> t_hist, y_hist;
  ASSERT_TRUE(SolveDynamic(model, s, options, [&](const DynamicStepReport& r, const DynamicState& st) {
                t_hist.push_back(r.t);
                y_hist.push_back(st.config.x[1].y());
              }).ok);
  double amplitude = 0;
  for (double y : y_hist) amplitude = std::max(amplitude, std::abs(y));
  std::vector<double> up_crossings;
  bool armed = false;
  for (size_t i = 1; i < y_hist.size(); ++i) {
    if (y_hist[i] < -0.5 * amplitude) armed = true;
    if (armed && y_hist[i - 1] < 0 && y_hist[i] >= 0) {
      up_crossings.push_back(t_hist[i - 1] +
                             (t_hist[i] - t_hist[i - 1]) * (-y_hist[i - 1]) / (y_hist[i] - y_hist[i - 1]));
      armed = false;
    }
  }
  ASSERT_GE(up_crossings.size(), 5u);
  const double measured = (up_crossings.size() - 1) / (up_crossings.back() - up_crossings.front());
  std::printf("[ info ] reduced model f1 = %.4f Hz, femb-solve ringing %.4f Hz (%zu periods)\n", f1, measured,
              up_crossings.size() - 1);
  EXPECT_NEAR(measured, f1, 0.005 * f1);
}

TEST(FlexibleDynamics, FreeSpinningFlexibleBodyConservesEnergyAndMomentum) {
  const Superelement se = Tube(4);
  SystemModel model;
  AddNode(model, "A", Eigen::Vector3d::Zero());
  AddNode(model, "B", Eigen::Vector3d(1, 0, 0));
  model.bodies.emplace_back(se, SuperelementOptions{});
  model.body_nodes.push_back({0, 1});
  // Spin about z through the centre (0.5, 0, 0) at 20 rad/s, plus a slight tumble about x.
  const Eigen::Vector3d omega(2.0, 0.0, 20.0), c(0.5, 0, 0);
  model.Number();
  Eigen::VectorXd W = Eigen::VectorXd::Zero(DofMap(model).n_dofs());
  W.segment<3>(0) = omega.cross(Eigen::Vector3d(0, 0, 0) - c);
  W.segment<3>(3) = omega;
  W.segment<3>(6) = omega.cross(Eigen::Vector3d(1, 0, 0) - c);
  W.segment<3>(9) = omega;
  const double period = 2 * M_PI / omega.norm();
  struct Errors {
    double dE = 0, dH = 0, dL = 0, max_elastic = 0;
  };
  // As femb-solve builds them: the midpoint scheme's body has the corotational inertia.
  SystemModel corotational = model;
  SuperelementOptions corotational_options;
  corotational_options.exact_inertia = false;
  corotational.bodies.clear();
  corotational.bodies.emplace_back(se, corotational_options);
  auto run = [&](int steps_per_turn, Integrator integrator) {
    const SystemModel& used = integrator == Integrator::kMidpoint ? corotational : model;
    DynamicState s = InitialDynamicState(used, InitialState(used), W);
    const DynamicStepReport r0 = Measure(used, s);
    DynamicOptions options;
    options.step = period / steps_per_turn;
    options.end_time = 5 * period;
    options.rho_inf = 1.0;
    options.integrator = integrator;
    Errors e;
    const double E0 = r0.kinetic_energy + r0.elastic_energy;
    EXPECT_TRUE(SolveDynamic(used, s, options, [&](const DynamicStepReport& r, const DynamicState&) {
                  e.dE = std::max(e.dE, std::abs(r.kinetic_energy + r.elastic_energy - E0) / E0);
                  e.dH = std::max(e.dH, (r.angular_momentum - r0.angular_momentum).norm() / r0.angular_momentum.norm());
                  e.dL = std::max(e.dL, r.linear_momentum.norm());
                  e.max_elastic = std::max(e.max_elastic, r.elastic_energy);
                }).ok);
    std::printf(
        "[ info ] free spin, %s, %d steps/turn: energy %.2e, angular momentum %.2e, linear momentum %.2e kg m/s, "
        "max elastic energy %.3e J of %.3e J\n",
        integrator == Integrator::kMidpoint ? "midpoint" : "generalized-alpha", steps_per_turn, e.dE, e.dH, e.dL,
        e.max_elastic, E0);
    return e;
  };
  const Errors coarse = run(200, Integrator::kGeneralizedAlpha), fine = run(400, Integrator::kGeneralizedAlpha);
  const double omega_h = 2 * M_PI / 200;
  EXPECT_GT(coarse.max_elastic, 0.0);  // centrifugal stretching and the tumble deform the tube
  // Method error, bounded and second order (as for the rigid body): below 2 (omega h)^2 and
  // about 4x smaller at half the step.
  EXPECT_LT(coarse.dE, 2 * omega_h * omega_h);
  EXPECT_LT(coarse.dH, omega_h * omega_h);
  EXPECT_GT(coarse.dE / fine.dE, 3.5);
  EXPECT_GT(coarse.dH / fine.dH, 3.5);
  // Linear momentum (initially zero) stays at round-off: mass 0.161 kg, speeds up to 10 m/s.
  EXPECT_LT(coarse.dL, 1e-9 * se.mass_properties.mass * 10.0);

  // The momentum-conserving midpoint scheme: angular and linear momentum and, through the free
  // body's energy closure (solver/integrators/midpoint_energy.cpp), the energy are invariants of
  // the discrete map also for the flexible body, to the Newton tolerance 1e-9 (measured: energy
  // 5.9e-12 and 2.2e-11 at 200 and 400 steps per turn, the momenta at round-off through
  // midpoint_momentum.cpp, which gives Newton's leftover back; without the closure a second-order
  // error, 5.8e-6 at 200).
  const Errors mid_coarse = run(200, Integrator::kMidpoint), mid_fine = run(400, Integrator::kMidpoint);
  EXPECT_GT(mid_coarse.max_elastic, 0.0);
  EXPECT_LT(mid_coarse.dH, 1e-8);
  EXPECT_LT(mid_fine.dH, 1e-8);
  EXPECT_LT(mid_coarse.dL, 1e-9 * se.mass_properties.mass * 10.0);
  EXPECT_LT(mid_coarse.dE, 1e-8);
  EXPECT_LT(mid_fine.dE, 1e-8);
}

// Two tubes, A-B on [0, 1] and C-D on [1.2, 2.2] along x, tumbling together about (1.1, 0, 0) at
// 5 rad/s: with `spherical` C hangs on B by a spherical joint (one free system, a chain), otherwise
// both are free and a spring-damper joins B and C (two free systems exchanging momentum).
struct TwoTubes {
  SystemModel model;
  Eigen::VectorXd W;
  double period = 0.0;
};
TwoTubes TwoTumblingTubes(const Superelement& se, bool spherical) {
  TwoTubes t;
  SystemModel& model = t.model;
  const Eigen::Vector3d x[4] = {{0, 0, 0}, {1, 0, 0}, {1.2, 0, 0}, {2.2, 0, 0}};
  for (int k = 0; k < 4; ++k) AddNode(model, std::string(1, char('A' + k)), spherical && k == 2 ? x[1] : x[k]);
  model.bodies.emplace_back(se, SuperelementOptions{});
  model.bodies.emplace_back(se, SuperelementOptions{});
  model.body_nodes = {{0, 1}, {2, 3}};
  if (spherical) {
    model.node_x0[3] = Eigen::Vector3d(2, 0, 0);
    model.joints.push_back(MakeNodeJoint(JointType::kSpherical, 2, 1, Eigen::Vector3d::UnitZ(), model.node_x0[1],
                                         model.node_R0[1], model.node_x0[2], model.node_R0[2]));
  } else {
    SpringDamper spring;
    spring.node_a = 1;
    spring.node_b = 2;
    spring.stiffness = 2e3;
    spring.damping = 1.0;
    spring.free_length = 0.25;  // stretched by 5 cm at the start
    model.springs.push_back(spring);
  }
  model.Number();
  const DofMap& dofs = model.dofs();
  const Eigen::Vector3d omega(1.0, 0.5, 5.0), c(1.1, 0, 0);
  t.W = Eigen::VectorXd::Zero(dofs.n_dofs());
  for (int k = 0; k < 4; ++k) {
    if (dofs.free(k)) {
      t.W.segment<3>(dofs.node_first(k)) = omega.cross(model.node_x0[k] - c);
      t.W.segment<3>(dofs.node_first(k) + 3) = omega;
    } else {
      t.W.segment<3>(dofs.node_first(k)) = omega;  // the spherical joint's rotation: spatial
    }
  }
  t.period = 2 * M_PI / omega.norm();
  return t;
}

// The midpoint scheme at steps of period / 100 for 3 periods, Newton tolerance `tolerance`: the
// largest change of the linear (kg m/s) and angular momentum (relative) and the last angular
// momentum.
struct MomentumDrift {
  double linear = 0.0, angular = 0.0;
  Eigen::Vector3d last = Eigen::Vector3d::Zero();
};
MomentumDrift MidpointMomentumDrift(const TwoTubes& t, double tolerance) {
  DynamicState s = InitialDynamicState(t.model, InitialState(t.model), t.W);
  const DynamicStepReport r0 = Measure(t.model, s);
  DynamicOptions options;
  options.integrator = Integrator::kMidpoint;
  options.step = t.period / 100;
  options.end_time = 3 * t.period;
  options.tolerance = tolerance;
  MomentumDrift d;
  EXPECT_TRUE(SolveDynamic(t.model, s, options, [&](const DynamicStepReport& r, const DynamicState&) {
                d.linear = std::max(d.linear, (r.linear_momentum - r0.linear_momentum).norm());
                d.angular =
                    std::max(d.angular, (r.angular_momentum - r0.angular_momentum).norm() / r0.angular_momentum.norm());
                d.last = r.angular_momentum;
              }).ok);
  return d;
}

// Newton's leftover does not reach the momenta (solver/integrators/midpoint_momentum.cpp): the
// converged step hands each free system the impulse its residual withheld. Two free tubes joined
// by a spring-damper keep the momenta of the pair at round-off at the loose tolerance 1e-6 as at
// 1e-12 (measured 1.5e-14 / 1.5e-14; without it the angular momentum drifted 8.0e-6 / 5.9e-10 in
// the 3 periods, the linear 6.3e-8 / 6.1e-13 kg m/s); a chain on a spherical joint ends with the
// same angular momentum at 1e-6 as at 1e-12, to 1e-11 (measured 2.0e-14; without, 2.0e-5).
TEST(FlexibleDynamics, MidpointKeepsTheMomentaWhateverNewtonsTolerance) {
  const Superelement se = Tube(4);
  const TwoTubes pair = TwoTumblingTubes(se, false), chain = TwoTumblingTubes(se, true);
  const MomentumDrift loose = MidpointMomentumDrift(pair, 1e-6), tight = MidpointMomentumDrift(pair, 1e-12);
  const MomentumDrift chain_loose = MidpointMomentumDrift(chain, 1e-6),
                      chain_tight = MidpointMomentumDrift(chain, 1e-12);
  const double chain_gap = (chain_loose.last - chain_tight.last).norm() / chain_tight.last.norm();
  std::printf(
      "[ info ] two free tubes on a spring, tolerance 1e-6 / 1e-12: angular momentum %.2e / %.2e, linear %.2e / %.2e "
      "kg m/s; chain on a spherical joint: angular momentum %.2e / %.2e, the two apart by %.2e\n",
      loose.angular, tight.angular, loose.linear, tight.linear, chain_loose.angular, chain_tight.angular, chain_gap);
  // Round-off: the momenta's sums of terms up to 0.3 kg m/s and 0.1 kg m^2/s.
  EXPECT_LT(loose.angular, 1e-12);
  EXPECT_LT(loose.linear, 1e-13);
  EXPECT_LT(chain_loose.linear, 1e-13);
  EXPECT_LT(chain_gap, 1e-11);
}

TEST(FlexibleDynamics, JacobianReuseGivesTheSameMotionWithFewerFactorizations) {
  const Superelement se = Tube(4);
  SystemModel model = ClampedTube(se);
  model.gravity = Eigen::Vector3d(0, -9.81, 0);  // the tube sags and rings under its weight
  auto run = [&](bool reuse, DynamicResult* result) {
    DynamicState s = InitialDynamicState(model, InitialState(model), Eigen::VectorXd::Zero(DofMap(model).n_dofs()));
    DynamicOptions options;
    options.step = 1e-3;
    options.end_time = 0.2;
    options.jacobian_reuse = reuse ? JacobianReuse::kSteps : JacobianReuse::kNone;
    *result = SolveDynamic(model, s, options);
    return s.config.x[1];
  };
  DynamicResult full, reused;
  const Eigen::Vector3d a = run(false, &full), b = run(true, &reused);
  ASSERT_TRUE(full.ok && reused.ok);
  std::printf("[ info ] full Newton: %ld iterations, %ld factorizations; reuse: %ld iterations, %ld factorizations\n",
              full.newton_iterations, full.factorizations, reused.newton_iterations, reused.factorizations);
  EXPECT_LT((a - b).norm(), 1e-8 * std::max(1.0, a.norm()));  // same converged motion
  EXPECT_LT(reused.factorizations, full.factorizations / 10);
}

// Modified Newton within the step (generalized-alpha's default, dynamic_step.h's
// IterationMatrix): one factorization per step while the later iterations contract the residual
// tenfold. The residual is exact, so the motion is full Newton's to the Newton tolerance; the
// reference is full Newton (kNone) on the same model: the clamped tube sagging and ringing
// under its weight from rest, 2 ms steps.
TEST(FlexibleDynamics, ReuseWithinTheStepGivesTheSameMotionWithOneFactorizationPerStep) {
  const Superelement se = Tube(4);
  SystemModel model = ClampedTube(se);
  model.gravity = Eigen::Vector3d(0, -9.81, 0);
  auto run = [&](std::optional<JacobianReuse> reuse, DynamicResult* result) {
    DynamicState s = InitialDynamicState(model, InitialState(model), Eigen::VectorXd::Zero(DofMap(model).n_dofs()));
    DynamicOptions options;
    options.step = 2e-3;
    options.end_time = 0.2;
    options.jacobian_reuse = reuse;
    *result = SolveDynamic(model, s, options);
    return s.config.x[1];
  };
  DynamicResult full, step, unset;
  const Eigen::Vector3d a = run(JacobianReuse::kNone, &full), b = run(JacobianReuse::kStep, &step);
  const Eigen::Vector3d c = run(std::nullopt, &unset);
  ASSERT_TRUE(full.ok && step.ok && unset.ok);
  std::printf(
      "[ info ] full Newton: %ld steps, %ld iterations, %ld factorizations; within the step: %ld iterations, "
      "%ld factorizations\n",
      full.steps, full.newton_iterations, full.factorizations, step.newton_iterations, step.factorizations);
  EXPECT_GT(full.newton_iterations, full.steps);              // the steps do iterate: the test has something to show
  EXPECT_LT((a - b).norm(), 1e-8 * std::max(1.0, a.norm()));  // same converged motion
  EXPECT_EQ(step.factorizations, step.steps);                 // every step factors once (all contract)
  EXPECT_LT(step.factorizations, full.factorizations);
  EXPECT_EQ((b - c).norm(), 0.0);  // generalized-alpha's default is kStep
}

TEST(FlexibleDynamics, BodiesOnSeveralThreadsGiveTheSameBits) {
  // A chain of 6 segments of 0.25 m, linear and stiffened ones alternating (bodies of different
  // cost, so the dynamic schedule hands them out in a different order each pass), clamped at
  // one end by a hinge turning at 2 rad/s, swinging under gravity: 1, 2 and 3 threads
  // must give the same bits (per-body slots added in body order, solver/parallel.h), with
  // either integrator.
  const std::string part =
      "name: seg\ntype: beam\nmaterial: {E: 70.0e9, nu: 0.3, rho: 2700}\n"
      "section: {shape: tube, outer_radius: 0.01, wall: 0.001}\n"
      "beam:\n  points: {A: [0, 0, 0], B: [0.25, 0, 0]}\n  segments: [{from: A, to: B, elements: 4}]\n"
      "interfaces: [{name: A}, {name: B}]\nreduction: {internal_modes: 2, keep_mesh: false}\n";
  const Superelement linear = test::Reduce(part, {"reduction.geometric_stiffening=false"});
  const Superelement stiffened = test::Reduce(part, {"reduction.geometric_stiffening=true"});
  SystemModel model;
  for (int i = 0; i <= 6; ++i) AddNode(model, "n" + std::to_string(i), Eigen::Vector3d(0.25 * i, 0, 0));
  RevoluteToGround(model, 0, Eigen::Vector3d(0, 0, 1));
  for (int i = 0; i < 6; ++i) {
    model.bodies.emplace_back(i % 2 ? stiffened : linear, SuperelementOptions{}, Eigen::Matrix3d::Identity(),
                              Eigen::Vector3d(0.25 * i, 0, 0));
    model.body_nodes.push_back({i, i + 1});
  }
  model.gravity = Eigen::Vector3d(0, -9.81, 0);
  auto run = [&](Integrator integrator, int threads) {
    model.Number();
    const DofMap dofs(model);
    Eigen::VectorXd W = Eigen::VectorXd::Zero(dofs.n_dofs());
    W[0] = 2.0;  // the hinge turns at 2 rad/s
    DynamicState s = InitialDynamicState(model, InitialState(model), W);
    DynamicOptions options;
    options.step = 1e-3;
    options.end_time = 0.05;
    options.threads = threads;
    options.integrator = integrator;
    const DynamicResult r = SolveDynamic(model, s, options);
    EXPECT_TRUE(r.ok) << r.message;
    return s;
  };
  for (Integrator integrator : {Integrator::kGeneralizedAlpha, Integrator::kMidpoint}) {
    const DynamicState one = run(integrator, 1);
    EXPECT_GT(one.config.x[6].norm(), 1.0);
    for (int threads : {2, 3}) {
      const DynamicState many = run(integrator, threads);
      for (int k = 0; k < model.n_nodes(); ++k) {
        EXPECT_TRUE(one.config.x[k] == many.config.x[k]) << threads << " threads, node " << k;
        EXPECT_TRUE(one.config.R[k] == many.config.R[k]) << threads << " threads, node " << k;
      }
      for (size_t b = 0; b < model.bodies.size(); ++b) EXPECT_TRUE(one.config.eta[b] == many.config.eta[b]);
      EXPECT_TRUE(one.W == many.W) << threads << " threads";
    }
  }
}

TEST(FlexibleDynamics, ModalDampingDecaysTheRingingAtTheGivenRatio) {
  // A tube clamped at both interfaces moves only in its internal (fixed-interface) modes; the
  // first one, set ringing, decays with the modal damping ratio zeta: the amplitude falls by
  // exp(-2 pi zeta / sqrt(1 - zeta^2)) per period (logarithmic decrement).
  const Superelement se = Tube(4);
  const double zeta = 0.02;
  SuperelementOptions options;
  options.modal_damping = zeta;
  SystemModel model = ClampedTube(se, options);
  Clamp(model, 1);
  model.Number();
  const DofMap dofs(model);
  Eigen::VectorXd W = Eigen::VectorXd::Zero(dofs.n_dofs());
  W[dofs.mode_dof(0)] = 1.0;  // first internal mode set ringing
  DynamicState s = InitialDynamicState(model, InitialState(model), W);
  const double f1 = se.internal_frequencies_hz[0];
  DynamicOptions o;
  o.step = 1 / (f1 * 400);
  o.end_time = 6 / f1;
  o.rho_inf = 1.0;
  std::vector<double> peaks;
  double e2 = 0, e1 = 0;
  ASSERT_TRUE(SolveDynamic(model, s, o, [&](const DynamicStepReport&, const DynamicState& st) {
                const double e0 = st.config.eta[0][0];
                if (e1 > e2 && e1 >= e0 && e1 > 0) peaks.push_back(e1);
                e2 = e1;
                e1 = e0;
              }).ok);
  ASSERT_GE(peaks.size(), 5u);
  const double delta = std::log(peaks.front() / peaks.back()) / (peaks.size() - 1);
  const double measured = delta / std::sqrt(4 * M_PI * M_PI + delta * delta);
  std::printf("[ info ] modal damping: given %.4f, measured %.5f\n", zeta, measured);
  EXPECT_NEAR(measured, zeta, 0.02 * zeta);
}

// The stiffened slider-crank (crank at 150 rad/s, the rod in two stiffened tube bodies) under
// Radau IIA at steps of `step`, Newton tolerance 1e-3, for 0.128 s.
DynamicResult RadauSliderCrank(double step, std::optional<JacobianReuse> reuse = std::nullopt) {
  const Superelement crank = test::TubeSegment(0.15, 2, true), rod = test::TubeSegment(0.25, 2, true);
  const SystemModel model = test::SliderCrankModel(crank, rod, 0.15, 0.25);
  DynamicState s = InitialDynamicState(model, InitialState(model), Eigen::VectorXd::Zero(model.dofs().n_dofs()));
  DynamicOptions options;
  options.integrator = Integrator::kRadau;
  options.step = step;
  options.end_time = 0.128;
  options.tolerance = 1e-3;
  options.jacobian_reuse = reuse;
  return SolveDynamic(model, s, options);
}

// Radau IIA at steps long for its Newton iteration: the slider-crank at 4 ms, 0.6 rad of the
// crank a step. Newton with the predictor's kept matrix diverges on some steps where one with a
// fresh matrix at every iteration converges (radau.cpp), so a step is cut only when that fails
// too: measured 1 step cut (13 without the second start).
TEST(FlexibleDynamics, RadauCutsALongStepOnlyWhenNewtonWithFreshMatricesFails) {
  const DynamicResult r = RadauSliderCrank(4e-3);
  ASSERT_TRUE(r.ok) << r.message;
  std::printf("[ info ] Radau IIA at 4 ms: %ld steps, %ld cut, %.2f Newton iterations a step\n", r.steps, r.newton_cuts,
              double(r.newton_iterations) / double(r.steps));
  EXPECT_LE(r.newton_cuts, 4);
}

// Radau IIA's Newton with kept matrices, at steps long enough that the predictor is far from the
// solution (the slider-crank at 2 ms): the predictor's matrices carry its wrong forces, so when
// the first correction leaves the residual far above the tolerance the matrices are computed anew
// at the first iterate (radau.cpp, kFarFromSolution). Then the kept matrices cost few iterations
// more than full Newton with fresh ones at every iteration: measured 2.27 against 2.11 a step.
// Kept from the predictor until an iteration contracted less than tenfold, they took 2.55 here,
// and 5.27 against full Newton's 3.05 on the example's rod at 2 ms.
TEST(FlexibleDynamics, RadauKeptMatricesConvergeAlmostAsFullNewtonOnLongSteps) {
  const DynamicResult kept = RadauSliderCrank(2e-3, JacobianReuse::kStep);
  const DynamicResult full = RadauSliderCrank(2e-3, JacobianReuse::kNone);
  ASSERT_TRUE(kept.ok && full.ok) << kept.message << full.message;
  const double kept_iterations = double(kept.newton_iterations) / double(kept.steps);
  const double full_iterations = double(full.newton_iterations) / double(full.steps);
  std::printf(
      "[ info ] Radau IIA at 2 ms: %.2f Newton iterations a step with kept matrices (%ld factorizations), %.2f "
      "with fresh ones at every iteration (%ld)\n",
      kept_iterations, kept.factorizations, full_iterations, full.factorizations);
  EXPECT_LE(kept_iterations, 1.2 * full_iterations);
  EXPECT_LT(kept.factorizations, full.factorizations);
}

}  // namespace
}  // namespace femb
