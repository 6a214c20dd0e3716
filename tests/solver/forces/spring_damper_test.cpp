// Spring-damper: stiffness and damping matrices against finite differences; a body on a spring
// oscillates at sqrt(k/m) / 2 pi and decays with the damping ratio c / (2 sqrt(k m)).
#include "solver/forces/spring_damper.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "solver/analysis/dynamic_analysis.h"
#include "test_util.h"

namespace femb {
namespace {

TEST(SpringDamper, MatricesMatchFiniteDifferences) {
  SpringDamper s;
  s.stiffness = 1e4;
  s.damping = 30;
  s.free_length = 0.7;
  const Eigen::Vector3d xa(0.1, 0.2, -0.3), xb(0.5, 1.0, 0.2), va(1, -2, 0.5), vb(-0.3, 0.4, 2);
  const SpringDamperForces f = EvaluateSpringDamper(s, xa, xb, va, vb);
  Eigen::Matrix<double, 6, 6> K_fd, C_fd;
  const double h = 1e-7;
  for (int i = 0; i < 6; ++i) {
    Eigen::Matrix<double, 6, 1> e = Eigen::Matrix<double, 6, 1>::Unit(i) * h;
    const auto xp = EvaluateSpringDamper(s, xa + e.head<3>(), xb + e.tail<3>(), va, vb);
    const auto xm = EvaluateSpringDamper(s, xa - e.head<3>(), xb - e.tail<3>(), va, vb);
    K_fd.col(i) = -(xp.f - xm.f) / (2 * h);
    const auto vp = EvaluateSpringDamper(s, xa, xb, va + e.head<3>(), vb + e.tail<3>());
    const auto vm = EvaluateSpringDamper(s, xa, xb, va - e.head<3>(), vb - e.tail<3>());
    C_fd.col(i) = -(vp.f - vm.f) / (2 * h);
  }
  EXPECT_LT((f.K - K_fd).norm(), 1e-6 * f.K.norm());
  EXPECT_LT((f.C - C_fd).norm(), 1e-6 * f.C.norm());
  // Action and reaction.
  EXPECT_LT((f.f.head<3>() + f.f.tail<3>()).norm(), 1e-12);
}

TEST(SpringDamper, BodyOnASpringOscillatesAndDecaysAsTheClosedForm) {
  // A symmetric cross: centre of mass at its only interface node, so the spring through it
  // drives translation only.
  const Superelement se = test::Reduce(
      "name: cross\ntype: beam\nmaterial: {E: 2.0e11, nu: 0.3, rho: 7800}\n"
      "section: {shape: circle, diameter: 0.01}\n"
      "beam:\n  points: {C: [0, 0, 0], A: [0.2, 0, 0], B: [-0.2, 0, 0], D: [0, 0.1, 0], E: [0, -0.1, 0]}\n"
      "  segments: [{from: C, to: A, elements: 2}, {from: C, to: B, elements: 2}, {from: C, to: D, elements: 2},\n"
      "             {from: C, to: E, elements: 2}]\n"
      "interfaces: [{name: C}]\nreduction: {internal_modes: 0, floating_frame: 'interface:C'}\n");
  const double m = se.mass_properties.mass, k = 2000.0, zeta = 0.02, c = 2 * zeta * std::sqrt(k * m);
  SystemModel model;
  AddNode(model, "C", Eigen::Vector3d::Zero());
  model.bodies.emplace_back(se, SuperelementOptions{});
  model.body_nodes.push_back({0});
  SpringDamper s;
  s.node_a = 0;
  s.node_b = -1;
  s.ground = Eigen::Vector3d(-0.5, 0, 0);
  s.stiffness = k;
  s.damping = c;
  s.free_length = 0.5;
  model.springs.push_back(s);
  Eigen::VectorXd W = Eigen::VectorXd::Zero(6);
  W[0] = 0.1;  // initial velocity along the spring
  model.Number();
  DynamicState state = InitialDynamicState(model, InitialState(model), W);
  const double f_n = std::sqrt(k / m) / (2 * M_PI), f_d = f_n * std::sqrt(1 - zeta * zeta);
  DynamicOptions options;
  options.step = 1 / (f_n * 400);
  options.end_time = 8 / f_n;
  options.rho_inf = 1.0;
  std::vector<double> t_peak, x_peak;
  double x2 = 0, x1 = 0, t1 = 0;
  ASSERT_TRUE(SolveDynamic(model, state, options, [&](const DynamicStepReport& r, const DynamicState& st) {
                const double x0 = st.config.x[0].x();
                if (x1 > x2 && x1 >= x0 && x1 > 0) {
                  t_peak.push_back(t1);
                  x_peak.push_back(x1);
                }
                x2 = x1;
                x1 = x0;
                t1 = r.t;
              }).ok);
  ASSERT_GE(t_peak.size(), 6u);
  const double f_measured = (t_peak.size() - 1) / (t_peak.back() - t_peak.front());
  const double delta = std::log(x_peak.front() / x_peak.back()) / (x_peak.size() - 1);
  const double zeta_measured = delta / std::sqrt(4 * M_PI * M_PI + delta * delta);
  std::printf("[ info ] f: closed form %.5f Hz, femb %.5f Hz; zeta: %.5f vs %.5f\n", f_d, f_measured, zeta,
              zeta_measured);
  EXPECT_NEAR(f_measured, f_d, 2e-3 * f_d);  // peaks located to one step: 1/400 of a period
  EXPECT_NEAR(zeta_measured, zeta, 0.02 * zeta);
}

}  // namespace
}  // namespace femb
