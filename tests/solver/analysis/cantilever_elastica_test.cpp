// Static cantilever tube of the seeds (L = 1 m, R = 0.01 m, wall 0.001 m, E = 70 GPa), split
// into superelements, clamped at the left, vertical tip force that stays vertical, against the
// elastica (an inextensible Euler-Bernoulli beam, solved here by shooting with RK4).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "solver/analysis/static_analysis.h"
#include "test_util.h"

namespace femb {
namespace {

constexpr double kE = 70e9, kRo = 0.01, kRi = 0.009, kL = 1.0;
const double kEI = kE * M_PI / 4 * (std::pow(kRo, 4) - std::pow(kRi, 4));

// Elastica of a cantilever under a tip load P that stays vertical: theta(s) the downward
// rotation, EI theta'' = -P cos(theta), theta(0) = 0, theta'(L) = 0. Its first integral
// EI theta'^2 / 2 = P (sin theta_L - sin theta) gives theta'(0) = sqrt(2 P sin(theta_L) / EI) for
// a tip angle theta_L in (0, pi/2); shooting on theta_L by bisection: the arc length at which
// theta' first reaches 0 (theta = theta_L) grows monotonically with theta_L and must equal L.
// RK4, 4000 steps.
// Returns the tip (horizontal shortening, downward deflection).
Eigen::Vector2d ElasticaTip(double P) {
  auto shoot = [&](double theta_L, Eigen::Vector2d* tip) {
    const int n = 4000;
    const double h = kL / n;
    Eigen::Vector4d y(0, std::sqrt(2 * P * std::sin(theta_L) / kEI), 0, 0);  // theta, theta', x, w
    auto rhs = [&](const Eigen::Vector4d& s) {
      return Eigen::Vector4d(s[1], -P / kEI * std::cos(s[0]), std::cos(s[0]), std::sin(s[0]));
    };
    bool stopped = false;  // theta' reached 0 before s = L
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector4d k1 = rhs(y), k2 = rhs(y + 0.5 * h * k1), k3 = rhs(y + 0.5 * h * k2), k4 = rhs(y + h * k3);
      y += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
      stopped |= y[1] < 0;
    }
    if (tip) *tip = Eigen::Vector2d(kL - y[2], y[3]);
    return stopped;
  };
  double lo = 1e-9, hi = M_PI / 2 - 1e-12;
  EXPECT_TRUE(shoot(lo, nullptr));
  EXPECT_FALSE(shoot(hi, nullptr));
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (shoot(mid, nullptr) ? lo : hi) = mid;
  }
  Eigen::Vector2d tip;
  shoot(0.5 * (lo + hi), &tip);
  return tip;
}

SystemModel TubeChain(int n_bodies, const SuperelementOptions& options, double P) {
  const double Lb = kL / n_bodies;
  char part[600];
  std::snprintf(part, sizeof part,
                "name: tube_segment\ntype: beam\nmaterial: {E: 70.0e9, nu: 0.3, rho: 2700}\n"
                "section: {shape: tube, outer_radius: 0.01, wall: 0.001}\n"
                "beam:\n  theory: euler_bernoulli\n  points: {A: [0, 0, 0], B: [%.17g, 0, 0]}\n"
                "  segments: [{from: A, to: B, elements: 4}]\n"
                "interfaces: [{name: A}, {name: B}]\nreduction: {internal_modes: 0}\n",
                Lb);
  const Superelement se = test::Reduce(part);
  SystemModel model;
  for (int i = 0; i <= n_bodies; ++i) AddNode(model, "n" + std::to_string(i), Eigen::Vector3d(i * Lb, 0, 0));
  Clamp(model, 0);
  for (int i = 0; i < n_bodies; ++i) {
    model.bodies.emplace_back(se, options, Eigen::Matrix3d::Identity(), Eigen::Vector3d(i * Lb, 0, 0));
    model.body_nodes.push_back({i, i + 1});
  }
  NodeLoad load;
  load.node = n_bodies;
  load.force = Eigen::Vector3d(0, -P, 0);
  model.loads.push_back(load);
  return model;
}

TEST(CantileverElastica, TenBodiesMatchTheElasticaWithin1PercentUpTo10kN) {
  const double P = 10e3;
  const SystemModel model = TubeChain(10, {false, true}, P);
  SystemState state = InitialState(model);
  StaticOptions options;
  options.steps = 100;  // 100 N per step, as in the seeds
  double worst = 0.0;
  std::printf("[ info ]      P [N]   iters  femb (du, w) [m]        elastica (du, w) [m]   rel. error\n");
  const StaticResult r = SolveStatic(model, state, options, [&](const StaticStepReport& s, const SystemState& st) {
    const Eigen::Vector3d tip = st.x[10];
    const Eigen::Vector2d femb(kL - tip.x(), -tip.y());
    const Eigen::Vector2d ref = ElasticaTip(s.lambda * P);
    const double error = (femb - ref).norm() / ref.norm();
    worst = std::max(worst, error);
    const int step = int(std::lround(s.lambda * 100));
    if (step % 10 == 0 || step == 1) {
      std::printf("[ info ] %10.0f %7d  (%.5f, %.5f)   (%.5f, %.5f)   %.2e\n", s.lambda * P, s.iterations, femb.x(),
                  femb.y(), ref.x(), ref.y(), error);
    }
  });
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_LT(worst, 0.01);
}

TEST(CantileverElastica, SmallLoadIsLinearBeamTheory) {
  // P = 1 N: tip deflection PL^3/3EI, one body and ten bodies.
  for (int n : {1, 10}) {
    const SystemModel model = TubeChain(n, {false, true}, 1.0);
    SystemState state = InitialState(model);
    StaticOptions options;
    options.steps = 1;
    ASSERT_TRUE(SolveStatic(model, state, options).ok);
    const double expected = kL * kL * kL / (3 * kEI);
    EXPECT_NEAR(-state.x[n].y(), expected, 1e-4 * expected) << n << " bodies";
  }
}

TEST(CantileverElastica, K1OnlyTangentFailsAtHighLoadWithAMessage) {
  // The paper's observation: without the geometric stiffness (K2 + K3) Newton loses
  // convergence as the load grows.
  const SystemModel model = TubeChain(10, {false, false}, 10e3);
  SystemState state = InitialState(model);
  StaticOptions options;
  options.steps = 100;
  const StaticResult r = SolveStatic(model, state, options);
  std::printf("[ info ] K1 only: %s after %zu converged steps\n", r.ok ? "converged" : r.message.c_str(), r.steps.size());
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("Newton did not converge at pseudo-time"), std::string::npos);
}

}  // namespace
}  // namespace femb
