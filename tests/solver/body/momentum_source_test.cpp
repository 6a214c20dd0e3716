// solver/body/momentum_source: the derivatives of the momentum source and of the momentum
// against finite differences, corotational and exact inertia.
#include "solver/body/momentum_source.h"

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

TEST(SuperelementBody, MomentumDerivativesMatchFiniteDifferences) {
  // d(M_g w)/dq at fixed spatial velocities w, options A and B, against central differences of
  // the momentum M_g w (the frame re-solved at each perturbed configuration); the derivatives
  // of MomentumSource in w and p likewise, and the inertia force's configuration derivative.
  for (bool option_b : {false, true}) {
    SuperelementOptions options;
    options.cardona_option_b = option_b;
    options.exact_inertia = false;  // the corotational inertia's momentum (thesis 3.22) is what is checked
    const SuperelementBody body(Tee(), options);
    const BodyConfiguration c = Deformed(body, 0.1, 5);
    const FrameSolution frame = SolveFrame(body, c, GuessFrame(body, c));
    const int n = body.n_coordinates();
    std::mt19937 rng(3);
    const Eigen::VectorXd w = Uniform(n, rng);
    const Eigen::MatrixXd D = test::MomentumDerivativeOf(body, test::MapsAt(body, c, frame), w);
    Eigen::MatrixXd fd(n, n);
    const double eps = 1e-6;
    for (int i = 0; i < n; ++i) {
      const Eigen::VectorXd e = Eigen::VectorXd::Unit(n, i);
      const BodyConfiguration cp = Perturb(c, e, eps), cm = Perturb(c, e, -eps);
      fd.col(i) = (test::MapsAt(body, cp, SolveFrame(body, cp, frame)).Mg * w -
                   test::MapsAt(body, cm, SolveFrame(body, cm, frame)).Mg * w) /
                  (2 * eps);
    }
    EXPECT_LT((D - fd).norm(), 1e-6 * fd.norm()) << (option_b ? "option B" : "option A");

    // MomentumSource derivatives in w and p (bilinear: central differences are exact up to
    // round-off).
    const Eigen::VectorXd p = Uniform(n, rng);
    Eigen::MatrixXd d_w, d_p, fd_w(n, n), fd_p(n, n);
    const BodyVelocityMaps maps = test::MapsAt(body, c, frame);
    BodyScratch scratch;
    MomentumSourceDerivatives(body, test::MapsAt(body, c, frame), w, p, d_w, d_p, scratch);
    for (int i = 0; i < n; ++i) {
      const Eigen::VectorXd e = Eigen::VectorXd::Unit(n, i);
      fd_w.col(i) = (test::MomentumSourceOf(body, maps, w + e, p) - test::MomentumSourceOf(body, maps, w - e, p)) / 2.0;
      fd_p.col(i) = (test::MomentumSourceOf(body, maps, w, p + e) - test::MomentumSourceOf(body, maps, w, p - e)) / 2.0;
    }
    EXPECT_LT((d_w - fd_w).norm(), 1e-12 * fd_w.norm()) << (option_b ? "option B" : "option A");
    EXPECT_LT((d_p - fd_p).norm(), 1e-12 * fd_p.norm()) << (option_b ? "option B" : "option A");

    // Configuration derivative of the inertia force: d(M_g wdot)/dq (analytic) against central
    // differences of f_in at w = 0 (where f_in = M_g wdot exactly), and the full derivative
    // (quadratic terms by differences inside the body) against differences of f_in.
    const Eigen::VectorXd wdot = Uniform(n, rng);
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
    for (bool full : {false, true}) {
      const Eigen::MatrixXd K_in =
          test::InertiaConfigurationTangentOf(body, Evaluate(body, c, frame), full ? w : zero, wdot, full);
      Eigen::MatrixXd fd_in(n, n);
      for (int i = 0; i < n; ++i) {
        const Eigen::VectorXd e = Eigen::VectorXd::Unit(n, i);
        const BodyConfiguration cp = Perturb(c, e, eps), cm = Perturb(c, e, -eps);
        Eigen::VectorXd fp, fm;
        InertiaForce(body, test::Lvalue(Evaluate(body, cp, SolveFrame(body, cp, frame))), full ? w : zero, wdot, &fp,
                     nullptr, nullptr);
        InertiaForce(body, test::Lvalue(Evaluate(body, cm, SolveFrame(body, cm, frame))), full ? w : zero, wdot, &fm,
                     nullptr, nullptr);
        fd_in.col(i) = (fp - fm) / (2 * eps);
      }
      EXPECT_LT((K_in - fd_in).norm(), 1e-5 * fd_in.norm())
          << (option_b ? "option B" : "option A") << (full ? ", full" : ", M_g wdot");
    }
  }
}

// The exact inertia's momentum p = MassTimes(d, w) (the midpoint scheme's): its configuration
// derivative at fixed w (MomentumConfigurationTangent: the frame's turning analytic, the local
// coordinates' share by differences in q_loc) against central differences of p with the frame
// re-solved at each perturbed configuration.
TEST(SuperelementBody, ExactMomentumConfigurationTangentMatchesFiniteDifferences) {
  const SuperelementBody body(Tee(), SuperelementOptions{});
  ASSERT_TRUE(body.has_exact_inertia());
  const BodyConfiguration c = Deformed(body, 0.1, 5);
  const FrameSolution frame = SolveFrame(body, c, GuessFrame(body, c));
  const int n = body.n_coordinates();
  std::mt19937 rng(3);
  const Eigen::VectorXd w = Uniform(n, rng);
  BodyData d = Evaluate(body, c, frame);
  BodyData side;
  Eigen::MatrixXd D;
  MomentumConfigurationTangent(body, d, w, side, D);
  Eigen::MatrixXd fd(n, n);
  const double eps = 1e-6;
  for (int i = 0; i < n; ++i) {
    const Eigen::VectorXd e = Eigen::VectorXd::Unit(n, i);
    const BodyConfiguration cp = Perturb(c, e, eps), cm = Perturb(c, e, -eps);
    BodyData dp = Evaluate(body, cp, SolveFrame(body, cp, frame));
    BodyData dm = Evaluate(body, cm, SolveFrame(body, cm, frame));
    fd.col(i) = (MassTimes(body, dp, w) - MassTimes(body, dm, w)) / (2 * eps);
  }
  std::printf("[ info ] exact momentum's configuration tangent against differences: %.2e\n",
              (D - fd).norm() / fd.norm());
  EXPECT_LT((D - fd).norm(), 1e-6 * fd.norm());
}

}  // namespace
}  // namespace femb
