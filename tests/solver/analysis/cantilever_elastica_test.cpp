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
  model.Number();
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
    const Eigen::Vector2d ref = test::ElasticaTip(s.lambda * P, kEI, kL);
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
  std::printf("[ info ] K1 only: %s after %zu converged steps\n", r.ok ? "converged" : r.message.c_str(),
              r.steps.size());
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("Newton did not converge at pseudo-time"), std::string::npos);
}

}  // namespace
}  // namespace femb
