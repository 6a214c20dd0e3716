// Helpers of the body kernels' tests (tests/solver/body): parts reduced in memory and
// configurations of a body, deformed or perturbed.
#pragma once

#include <Eigen/Geometry>
#include <random>
#include <string>

#include "solver/body/superelement_body.h"
#include "solver/rotation.h"
#include "test_util.h"

namespace femb::body_test {

inline Superelement Rod(const std::string& frame, int modes = 3) {
  return test::Reduce(test::StraightBeamYaml(
                          0.5, 8, "{shape: rectangle, width: 0.02, height: 0.01}", "{E: 7.0e10, nu: 0.3, rho: 2700}",
                          "[{name: A}, {name: B}]",
                          "reduction: {internal_modes: " + std::to_string(modes) + ", geometric_stiffening: false}\n"),
                      {"reduction.floating_frame=" + frame});
}

// A three-interface part (T-shape) to exercise N > 2.
inline Superelement Tee() {
  return test::Reduce(
      "name: tee\ntype: beam\nmaterial: {E: 7.0e10, nu: 0.3, rho: 2700}\n"
      "section: {shape: circle, diameter: 0.01}\n"
      "beam:\n  points: {A: [0, 0, 0], C: [0.2, 0, 0], B: [0.4, 0, 0], D: [0.2, 0.3, 0]}\n"
      "  segments: [{from: A, to: C, elements: 3}, {from: C, to: B, elements: 3}, {from: C, to: D, elements: 3}]\n"
      "interfaces: [{name: A}, {name: B}, {name: D}]\n"
      "reduction: {internal_modes: 2, floating_frame: mean_axes, geometric_stiffening: false}\n");
}

// n entries uniform in [-1, 1], drawn in order from `rng`.
inline Eigen::VectorXd Uniform(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v[i] = u(rng);
  return v;
}

// A deformed configuration: large rigid rotation and translation, plus node perturbations of
// the given size (displacements relative to the body size, rotations in rad).
inline BodyConfiguration Deformed(const SuperelementBody& body, double size, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  BodyConfiguration c = InitialConfiguration(body);
  const Eigen::Matrix3d Rr = ExpSO3(Eigen::Vector3d(0.7, -1.1, 0.4));
  const Eigen::Vector3d tr(0.3, -0.2, 1.5);
  for (int k = 0; k < body.n_nodes(); ++k) {
    c.x[k] = Rr * c.x[k] + tr + 0.05 * size * Eigen::Vector3d(u(rng), u(rng), u(rng));
    c.R[k] = ExpSO3(size * Eigen::Vector3d(u(rng), u(rng), u(rng))) * Rr * c.R[k];
  }
  for (int m = 0; m < c.eta.size(); ++m) c.eta[m] = 1e-3 * size * u(rng);
  return c;
}

// Applies eps * e (per node dx, dpi spatial; then d eta).
inline BodyConfiguration Perturb(const BodyConfiguration& c, const Eigen::VectorXd& e, double eps) {
  BodyConfiguration p = c;
  for (size_t k = 0; k < c.x.size(); ++k) {
    p.x[k] += eps * e.segment<3>(6 * k);
    p.R[k] = ExpSO3(eps * Eigen::Vector3d(e.segment<3>(6 * k + 3))) * c.R[k];
  }
  p.eta += eps * e.tail(c.eta.size());
  return p;
}

}  // namespace femb::body_test
