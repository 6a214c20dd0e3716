// solver/body/inertia_force: the gyroscopic matrix against finite differences of the inertia
// force and the mass as P^T M P; the inertia force as the Lagrangian derivative along a motion.
#include "solver/body/inertia_force.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "body_test_util.h"
#include "solver/body/superelement_body.h"
#include "solver/rotation.h"
#include "test_util.h"

namespace femb {
namespace {

using namespace body_test;

TEST(SuperelementBody, GyroscopicMatrixMatchesFiniteDifferencesAndMassIsPtMP) {
  for (bool option_b : {false, true}) {
    SuperelementOptions options;
    options.cardona_option_b = option_b;
    const SuperelementBody body(Tee(), options);
    const BodyConfiguration c = Deformed(body, 0.2, 11);
    const FrameSolution frame = SolveFrame(body, c, GuessFrame(body, c));
    ASSERT_TRUE(frame.ok);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const int n = body.n_coordinates();
    Eigen::VectorXd w(n), wdot(n);
    for (int i = 0; i < n; ++i) {
      w[i] = 3.0 * u(rng);
      wdot[i] = 10.0 * u(rng);
    }
    Eigen::VectorXd f;
    Eigen::MatrixXd Mg, C;
    InertiaForce(body, test::Lvalue(Evaluate(body, c, frame)), w, wdot, &f, &Mg, &C);
    Eigen::MatrixXd C_fd(n, n), M_fd(n, n);
    for (int i = 0; i < n; ++i) {
      const double h = 1e-6;
      Eigen::VectorXd fp, fm;
      InertiaForce(body, test::Lvalue(Evaluate(body, c, frame)), w + h * Eigen::VectorXd::Unit(n, i), wdot, &fp,
                   nullptr, nullptr);
      InertiaForce(body, test::Lvalue(Evaluate(body, c, frame)), w - h * Eigen::VectorXd::Unit(n, i), wdot, &fm,
                   nullptr, nullptr);
      C_fd.col(i) = (fp - fm) / (2 * h);
      InertiaForce(body, test::Lvalue(Evaluate(body, c, frame)), w, wdot + h * Eigen::VectorXd::Unit(n, i), &fp,
                   nullptr, nullptr);
      InertiaForce(body, test::Lvalue(Evaluate(body, c, frame)), w, wdot - h * Eigen::VectorXd::Unit(n, i), &fm,
                   nullptr, nullptr);
      M_fd.col(i) = (fp - fm) / (2 * h);
    }
    EXPECT_LT((C - C_fd).norm(), 1e-6 * C.norm()) << "option B " << option_b;
    EXPECT_LT((Mg - M_fd).norm(), 1e-6 * Mg.norm());
    EXPECT_GT(C.norm(), 0.0);
    // The kinetic energy is w^T M_g w / 2.
    EXPECT_NEAR(KineticEnergy(body, test::Lvalue(Evaluate(body, c, frame)), w), 0.5 * w.dot(Mg * w),
                1e-12 * w.dot(Mg * w));
  }
}

TEST(SuperelementBody, InertiaForceIsTheLagrangianDerivativeAlongAMotion) {
  // Along a smooth motion q(t), d/dt (dT/dw) - (dT/dq) = f_in and the power balance
  // dT/dt = w . f_in holds for the inertia force, corotational (thesis 3.22) and exact. Check the
  // power balance with central differences in time on a rigid-deformable motion of the Tee; the
  // momentum form of the midpoint integrator with the corotational inertia.
  for (const bool exact : {false, true}) {
    SuperelementOptions options;
    options.exact_inertia = exact;
    const SuperelementBody body(Tee(), options);
    ASSERT_EQ(body.has_exact_inertia(), exact);
    const BodyConfiguration c0 = Deformed(body, 0.1, 21);
    const int n = body.n_coordinates();
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Eigen::VectorXd w0(n), acc(n);
    for (int i = 0; i < n; ++i) {
      w0[i] = u(rng);
      acc[i] = u(rng);
    }
    // q(t) = q0 o exp(t w0 + t^2/2 acc) (node-wise), w(t) = w0 + t acc to first order; use the
    // exact velocity of this curve through the discrete derivative of positions and rotations.
    auto config = [&](double t) { return Perturb(c0, t * w0 + 0.5 * t * t * acc, 1.0); };
    auto velocity = [&](double t) {
      const double h = 1e-6;
      const BodyConfiguration a = config(t - h), b = config(t + h);
      Eigen::VectorXd w(n);
      for (int k = 0; k < body.n_nodes(); ++k) {
        w.segment<3>(6 * k) = (b.x[k] - a.x[k]) / (2 * h);
        w.segment<3>(6 * k + 3) = LogSO3(b.R[k] * a.R[k].transpose()) / (2 * h);
      }
      w.tail(body.n_modes()) = (b.eta - a.eta) / (2 * h);
      return w;
    };
    auto energy = [&](double t) {
      const BodyConfiguration c = config(t);
      return KineticEnergy(body, test::Lvalue(Evaluate(body, c, SolveFrame(body, c, GuessFrame(body, c)))),
                           velocity(t));
    };
    const double t = 0.01, dt = 1e-4;
    const double power_fd = (energy(t + dt) - energy(t - dt)) / (2 * dt);
    const BodyConfiguration c = config(t);
    const Eigen::VectorXd w = velocity(t);
    const Eigen::VectorXd wdot = (velocity(t + dt) - velocity(t - dt)) / (2 * dt);
    Eigen::VectorXd f_in;
    InertiaForce(body, test::Lvalue(Evaluate(body, c, SolveFrame(body, c, GuessFrame(body, c)))), w, wdot, &f_in,
                 nullptr, nullptr);
    EXPECT_NEAR(w.dot(f_in), power_fd, 1e-5 * std::abs(power_fd)) << (exact ? "exact" : "corotational");
    if (exact) {
      // The exact inertia's momentum form (the midpoint scheme with the exact inertia):
      // p = MassTimes (dT/dw), s = MomentumSource at the body's data, with its local term.
      auto momentum_exact = [&](double time) {
        const BodyConfiguration ct = config(time);
        BodyData data = Evaluate(body, ct, SolveFrame(body, ct, GuessFrame(body, ct)));
        return Eigen::VectorXd(MassTimes(body, data, velocity(time)));
      };
      const Eigen::VectorXd pdot_exact = (momentum_exact(t + dt) - momentum_exact(t - dt)) / (2 * dt);
      BodyData d = Evaluate(body, c, SolveFrame(body, c, GuessFrame(body, c)));
      const Eigen::VectorXd p = MassTimes(body, d, w);
      Eigen::VectorXd source;
      MomentumSource(body, d, w, p, source);
      const Eigen::VectorXd balance = pdot_exact - source;
      std::printf("[ info ] exact inertia: momentum form against f_in %.2e (relative)\n",
                  (balance - f_in).norm() / f_in.norm());
      EXPECT_LT((balance - f_in).norm(), 1e-5 * f_in.norm())
          << "exact: f_in " << f_in.transpose() << "\nbalance " << balance.transpose();
      continue;
    }

    // Momentum form used by the midpoint integrator: f_in = dp/dt - s(q, w, p), p = M_g w,
    // s = MomentumSource; dp/dt by central differences along the same motion.
    auto momentum = [&](double time) -> Eigen::VectorXd {
      const BodyConfiguration ct = config(time);
      return test::MapsAt(body, ct, SolveFrame(body, ct, GuessFrame(body, ct))).Mg * velocity(time);
    };
    const Eigen::VectorXd pdot = (momentum(t + dt) - momentum(t - dt)) / (2 * dt);
    const FrameSolution frame = SolveFrame(body, c, GuessFrame(body, c));
    const BodyVelocityMaps maps = test::MapsAt(body, c, frame);
    const Eigen::VectorXd balance = pdot - test::MomentumSourceOf(body, maps, w, maps.Mg * w);
    EXPECT_LT((balance - f_in).norm(), 1e-5 * f_in.norm())
        << "f_in " << f_in.transpose() << "\nbalance " << balance.transpose();
  }
}

}  // namespace
}  // namespace femb
