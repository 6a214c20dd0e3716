// The three-stage Radau IIA integrator (solver/integrators/radau.cpp) against rigid-body
// invariants: a torque-free body with three unequal principal moments (a free node: the stages'
// rotations through the inverse left Jacobian) keeps its energy and angular momentum to the
// scheme's error, which falls at fifth order with the step; fixed steps only (one message).
// Closed loops: tests/solver/analysis/dynamic_consistency_test.cpp.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>

#include "solver/analysis/dynamic_analysis.h"
#include "test_util.h"

namespace femb {
namespace {

// Three unequal arms from the centre C, held at C (its centre of mass).
Superelement Jack() {
  return test::Reduce(
      "name: jack\ntype: beam\nmaterial: {E: 2.0e11, nu: 0.3, rho: 7800}\n"
      "section: {shape: circle, diameter: 0.01}\n"
      "beam:\n  points: {C: [0, 0, 0], A: [0.3, 0, 0], B: [0, 0.2, 0], D: [0, 0, 0.1], E: [-0.3, 0, 0], F: [0, -0.2, "
      "0], G: [0, 0, -0.1]}\n"
      "  segments: [{from: C, to: A, elements: 4}, {from: C, to: B, elements: 4}, {from: C, to: D, elements: 2},\n"
      "             {from: C, to: E, elements: 4}, {from: C, to: F, elements: 4}, {from: C, to: G, elements: 2}]\n"
      "interfaces: [{name: C}]\nreduction: {internal_modes: 0, floating_frame: 'interface:C'}\n");
}

struct Flight {
  DynamicResult result;
  double energy_error = 0, momentum_error = 0;
};

// Free flight spinning at omega0 (spatial), n_steps of h with the Radau IIA integrator.
Flight FreeFlight(const Superelement& se, const Eigen::Vector3d& omega0, double h, int n_steps, bool adaptive = false) {
  SystemModel model;
  AddNode(model, "C", se.interfaces[0].position);
  model.bodies.emplace_back(se, SuperelementOptions{});
  model.body_nodes.push_back({0});
  Eigen::VectorXd W(6);
  W << omega0.cross(se.interfaces[0].position - se.mass_properties.center_of_mass), omega0;
  DynamicState s = InitialDynamicState(model, InitialState(model), W);
  const DynamicStepReport r0 = Measure(model, s);
  DynamicOptions options;
  options.integrator = Integrator::kRadau;
  options.step = h;
  options.end_time = h * n_steps;
  options.tolerance = 1e-12;
  options.adaptive = adaptive;
  Flight f;
  f.result = SolveDynamic(model, s, options, [&](const DynamicStepReport& r, const DynamicState&) {
    f.energy_error = std::max(f.energy_error, std::abs(r.kinetic_energy - r0.kinetic_energy) / r0.kinetic_energy);
    f.momentum_error =
        std::max(f.momentum_error, (r.angular_momentum - r0.angular_momentum).norm() / r0.angular_momentum.norm());
  });
  return f;
}

TEST(Radau, TorqueFreeBodyKeepsItsInvariantsToFifthOrder) {
  const Superelement se = Jack();
  const Eigen::Vector3d omega0(1.0, 2.0, 3.0);
  const double period = 2 * M_PI / omega0.norm();
  // Ten revolutions at 20 and 40 steps per revolution (omega h = 0.31 and 0.16).
  const Flight coarse = FreeFlight(se, omega0, period / 20, 200);
  const Flight fine = FreeFlight(se, omega0, period / 40, 400);
  ASSERT_TRUE(coarse.result.ok) << coarse.result.message;
  ASSERT_TRUE(fine.result.ok) << fine.result.message;
  std::printf("[ info ] 20 steps/rev: energy %.3e momentum %.3e; 40 steps/rev: energy %.3e momentum %.3e\n",
              coarse.energy_error, coarse.momentum_error, fine.energy_error, fine.momentum_error);
  // Generalized-alpha needs 100 steps per revolution for a momentum error of 1.8e-3
  // (rigid_body_dynamics_test.cpp); this scheme keeps both invariants below 1e-4 at 20.
  EXPECT_LT(coarse.momentum_error, 1e-4);
  EXPECT_LT(coarse.energy_error, 1e-4);
  // Fifth order: halving the step divides the errors by about 32 (at least 2^4.3 = 20 here).
  EXPECT_GT(coarse.momentum_error / fine.momentum_error, 20.0);
  EXPECT_GT(coarse.energy_error / fine.energy_error, 20.0);
}

TEST(Radau, RefusesErrorControlledSteps) {
  const Flight f = FreeFlight(Jack(), Eigen::Vector3d(1, 2, 3), 0.01, 10, true);
  EXPECT_FALSE(f.result.ok);
  EXPECT_NE(f.result.message.find("fixed steps"), std::string::npos) << f.result.message;
}

}  // namespace
}  // namespace femb
