// Linearized modes: about the undeformed state they are the reduced model's frequencies; under
// axial compression the geometric stiffness (K2 + K3) lowers the first frequency to zero at the
// Euler buckling load of the cantilever, P_cr = pi^2 EI / (4 L^2).
#include "solver/analysis/modal_analysis.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>

#include "solver/analysis/static_analysis.h"
#include "test_util.h"

namespace femb {
namespace {

constexpr double kE = 70e9;
const double kEI = kE * M_PI / 4 * (std::pow(0.01, 4) - std::pow(0.009, 4));

SystemModel Chain(int n_bodies, double axial_force) {
  const double Lb = 1.0 / n_bodies;
  const Superelement se = test::Reduce(
      "name: seg\ntype: beam\nmaterial: {E: 70.0e9, nu: 0.3, rho: 2700}\n"
      "section: {shape: tube, outer_radius: 0.01, wall: 0.001}\n"
      "beam:\n  theory: euler_bernoulli\n  points: {A: [0, 0, 0], B: [" +
      std::to_string(Lb) +
      ", 0, 0]}\n"
      "  segments: [{from: A, to: B, elements: 4}]\n"
      "interfaces: [{name: A}, {name: B}]\nreduction: {internal_modes: 2}\n");
  SystemModel model;
  for (int i = 0; i <= n_bodies; ++i) AddNode(model, "n" + std::to_string(i), Eigen::Vector3d(i * Lb, 0, 0));
  Clamp(model, 0);
  for (int i = 0; i < n_bodies; ++i) {
    model.bodies.emplace_back(se, SuperelementOptions{}, Eigen::Matrix3d::Identity(), Eigen::Vector3d(i * Lb, 0, 0));
    model.body_nodes.push_back({i, i + 1});
  }
  NodeLoad load;
  load.node = n_bodies;
  load.force = Eigen::Vector3d(-axial_force, 0, 0);  // compression
  model.loads.push_back(load);
  model.Number();
  return model;
}

TEST(ModalAnalysis, UndeformedModesAreTheReducedModelFrequencies) {
  SystemModel model = Chain(1, 0.0);
  SystemState state = InitialState(model);
  const ModalResult r = LinearizedModes(model, state, 0.0);
  ASSERT_TRUE(r.ok) << r.message;
  const Superelement& dummy = test::Reduce(
      "name: seg\ntype: beam\nmaterial: {E: 70.0e9, nu: 0.3, rho: 2700}\n"
      "section: {shape: tube, outer_radius: 0.01, wall: 0.001}\n"
      "beam:\n  theory: euler_bernoulli\n  points: {A: [0, 0, 0], B: [1.000000, 0, 0]}\n"
      "  segments: [{from: A, to: B, elements: 4}]\n"
      "interfaces: [{name: A}, {name: B}]\nreduction: {internal_modes: 2}\n");
  const int n = dummy.n_reduced_dofs();
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(dummy.K.bottomRightCorner(n - 6, n - 6),
                                                                dummy.M.bottomRightCorner(n - 6, n - 6));
  for (int k = 0; k < n - 6; ++k) {
    const double f = std::sqrt(eig.eigenvalues()[k]) / (2 * M_PI);
    EXPECT_NEAR(r.frequencies_hz[k], f, 1e-8 * f) << k;
  }
}

TEST(ModalAnalysis, CompressionLowersTheFirstFrequencyToZeroAtEulerBuckling) {
  const double P_cr = M_PI * M_PI * kEI / 4.0;  // L = 1
  double f0 = 0;
  std::printf("[ info ]  P / P_cr   f1 [Hz]   (f1/f0)^2\n");
  double p_zero = -1, previous_f = 0, previous_p = 0;
  for (double ratio : {0.0, 0.25, 0.5, 0.75, 0.95, 0.99, 1.01, 1.05}) {
    SystemModel model = Chain(10, ratio * P_cr);
    SystemState state = InitialState(model);
    StaticOptions options;
    options.steps = 1;
    ASSERT_TRUE(SolveStatic(model, state, options).ok);  // straight compressed state
    const ModalResult r = LinearizedModes(model, state, 1.0, 3);
    ASSERT_TRUE(r.ok);
    const double f1 = r.frequencies_hz[0];
    if (ratio == 0.0) f0 = f1;
    std::printf("[ info ] %8.2f %10.4f %10.4f\n", ratio, f1, f1 * std::abs(f1) / (f0 * f0));
    if (p_zero < 0 && previous_f > 0 && f1 <= 0) {
      // Interpolate lambda = f|f| linearly in P between the last two loads.
      const double l0 = previous_f * previous_f, l1 = f1 * std::abs(f1);
      p_zero = previous_p + (ratio - previous_p) * l0 / (l0 - l1);
    }
    previous_f = f1;
    previous_p = ratio;
  }
  // (f1/f0)^2 falls about linearly with P (Galef); it crosses zero at P_cr within 1%.
  ASSERT_GT(p_zero, 0);
  EXPECT_NEAR(p_zero, 1.0, 0.01);
}

}  // namespace
}  // namespace femb
