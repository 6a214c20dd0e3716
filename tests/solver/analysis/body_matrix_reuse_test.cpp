// The bodies' matrices kept in their floating frames (DynamicOptions::body_matrices_every):
//  - the premise: a body's matrices turn with it. Turning a deformed, moving body as a whole by Q
//    (node positions, rotations, velocities, accelerations) turns every node block of its
//    elastic tangent (with the inertia stiffening and its velocity and acceleration parts), mass,
//    gyroscopic and inertia configuration tangent: X(Q) = Qbar X Qbar^T to round-off (measured
//    4e-17 to 2e-14 relative; bound 1e-12). For a linear body with the corotational inertia and
//    for a stiffened one with the exact inertia;
//  - a stiffened slider-crank (crank driven at 150 rad/s, rod in 2 bodies, gravity) with the
//    bodies' matrices computed every 4th step (the others turned with the frames) takes the same
//    motion as with them computed every step, within the Newton tolerance, and computes a quarter
//    of them: with the inertia's matrices kept (BodyMatricesKept::kInertia), and with all of
//    them (kAll).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cstdio>
#include <string>

#include "solver/analysis/dynamic_analysis.h"
#include "solver/body/superelement_body.h"
#include "solver/rotation.h"
#include "test_util.h"

namespace femb {
namespace {

Superelement Tube(double L, bool stiffened) { return test::TubeSegment(L, 8, stiffened); }

struct BodyMatrices {
  Eigen::MatrixXd K, K_load_w, K_load_wdot, M, G, K_inertia;
};

BodyMatrices MatricesAt(const SuperelementBody& body, const BodyConfiguration& c, const FrameSolution& f,
                        const Eigen::VectorXd& w, const Eigen::VectorXd& wdot) {
  BodyData d = Evaluate(body, c, f);
  BodyMatrices m;
  if (body.has_inertia_stiffening()) {
    const InertiaLoadFactors load = test::InertiaLoadsOf(body, d, w, wdot, Eigen::Vector3d::Zero());
    Eigen::MatrixXd d_load;
    ElasticForce(body, d, nullptr, &m.K, &load, &d_load);
    m.K_load_w = d_load * load.d_w;
    m.K_load_wdot = d_load * load.d_wdot;
  } else {
    ElasticForce(body, d, nullptr, &m.K);
  }
  InertiaForce(body, d, w, wdot, nullptr, &m.M, &m.G);
  m.K_inertia = test::InertiaConfigurationTangentOf(body, d, w, wdot, false);
  return m;
}

TEST(BodyMatrices, TurnWithTheBody) {
  const Eigen::Matrix3d Q = ExpSO3(Eigen::Vector3d(0.7, -0.4, 1.1));
  for (const bool stiffened : {false, true}) {
    SuperelementOptions options;
    options.exact_inertia = stiffened;  // linear with the corotational inertia, stiffened with the exact one
    const SuperelementBody body(Tube(0.5, stiffened), options);
    ASSERT_EQ(body.has_exact_inertia(), stiffened);
    const int n = body.n_coordinates(), N = body.n_nodes();
    // A deformed, turned body with node velocities and accelerations of a few m/s, rad/s.
    BodyConfiguration c = InitialConfiguration(body);
    const Eigen::Matrix3d Rg = ExpSO3(Eigen::Vector3d(0.3, -0.2, 0.5));
    for (int k = 0; k < N; ++k) {
      c.x[k] = Rg * c.x[k] + Eigen::Vector3d(0.1, 0.2, -0.3) + 2e-3 * Eigen::Vector3d(k, -k, 2 * k);
      c.R[k] = ExpSO3(Eigen::Vector3d(0.02 * k, 0.01, -0.03 * k)) * Rg * c.R[k];
    }
    c.eta = Eigen::VectorXd::LinSpaced(body.n_modes(), 1e-3, -2e-3);
    const Eigen::VectorXd w = Eigen::VectorXd::LinSpaced(n, -1.0, 1.3);
    const Eigen::VectorXd wdot = Eigen::VectorXd::LinSpaced(n, 40.0, -55.0);
    // The same body turned by Q as a whole.
    BodyConfiguration cq = c;
    Eigen::VectorXd wq = w, wdotq = wdot;
    for (int k = 0; k < N; ++k) {
      cq.x[k] = Q * c.x[k];
      cq.R[k] = Q * c.R[k];
    }
    for (int a = 0; a < 2 * N; ++a) {
      wq.segment<3>(3 * a) = Q * w.segment<3>(3 * a);
      wdotq.segment<3>(3 * a) = Q * wdot.segment<3>(3 * a);
    }
    const FrameSolution f = SolveFrame(body, c, GuessFrame(body, c)), fq = SolveFrame(body, cq, GuessFrame(body, cq));
    ASSERT_TRUE(f.ok && fq.ok);
    EXPECT_LT((fq.R - Q * f.R).norm(), 1e-12);
    Eigen::MatrixXd Qbar = Eigen::MatrixXd::Identity(n, n);
    for (int a = 0; a < 2 * N; ++a) Qbar.block<3, 3>(3 * a, 3 * a) = Q;
    const BodyMatrices m = MatricesAt(body, c, f, w, wdot), mq = MatricesAt(body, cq, fq, wq, wdotq);
    const auto check = [&](const Eigen::MatrixXd& X, const Eigen::MatrixXd& Xq, const char* what) {
      const Eigen::MatrixXd turned = Qbar * X * Qbar.transpose();
      const double error = (Xq - turned).norm() / X.norm();
      std::printf("[ info ] %s body, %s: |X(Q) - Qbar X Qbar^T| / |X| = %.1e\n", stiffened ? "stiffened" : "linear",
                  what, error);
      EXPECT_LT(error, 1e-12) << what;
    };
    check(m.K, mq.K, "elastic tangent");
    check(m.M, mq.M, "mass");
    check(m.G, mq.G, "gyroscopic");
    check(m.K_inertia, mq.K_inertia, "inertia configuration tangent");
    if (stiffened) {
      check(m.K_load_w, mq.K_load_w, "stiffening, velocity part");
      check(m.K_load_wdot, mq.K_load_wdot, "stiffening, acceleration part");
    }
  }
}

TEST(BodyMatrices, KeptInTheirFramesGiveTheSameMotion) {
  // The crank and the two rod bodies stiffened (exact inertia), gravity.
  const SystemModel model = test::SliderCrankModel(Tube(0.15, true), Tube(0.25, true), 0.15, 0.25);
  const int mid = 3;  // rod_mid
  struct Run {
    DynamicResult result;
    std::vector<Eigen::Vector3d> mid_path;
  };
  const auto run = [&](int every, BodyMatricesKept kept) {
    DynamicState s = InitialDynamicState(model, InitialState(model), Eigen::VectorXd::Zero(model.dofs().n_dofs()));
    DynamicOptions options;
    options.step = 1e-4;
    options.end_time = 0.042;  // one crank revolution, 420 steps
    options.rho_inf = 0.8;
    options.body_matrices_every = every;
    options.body_matrices_kept = kept;
    Run r;
    r.result = SolveDynamic(model, s, options, [&](const DynamicStepReport&, const DynamicState& st) {
      r.mid_path.push_back(st.config.x[mid]);
    });
    return r;
  };
  const Run every_step = run(1, BodyMatricesKept::kAll);
  for (const BodyMatricesKept kept : {BodyMatricesKept::kInertia, BodyMatricesKept::kAll}) {
    const char* which = kept == BodyMatricesKept::kAll ? "all" : "inertia";
    SCOPED_TRACE(which);
    const Run every_4th = run(4, kept);
    ASSERT_TRUE(every_step.result.ok) << every_step.result.message;
    ASSERT_TRUE(every_4th.result.ok) << every_4th.result.message;
    ASSERT_EQ(every_step.mid_path.size(), every_4th.mid_path.size());
    double largest = 0.0, travel = 0.0;
    for (size_t i = 0; i < every_step.mid_path.size(); ++i) {
      largest = std::max(largest, (every_4th.mid_path[i] - every_step.mid_path[i]).norm());
      travel = std::max(travel, (every_step.mid_path[i] - model.node_x0[mid]).norm());
    }
    const DynamicResult &r1 = every_step.result, &r4 = every_4th.result;
    std::printf(
        "[ info ] every step: %ld iterations, %ld body matrices computed; every 4th (%s kept): %ld iterations, "
        "%ld computed, %ld turned; rod midpoint paths differ by %.1e m (it travels %.2f m)\n",
        r1.newton_iterations, r1.body_matrices_computed, which, r4.newton_iterations, r4.body_matrices_computed,
        r4.body_matrices_turned, largest, travel);
    EXPECT_EQ(r1.body_matrices_turned, 0);
    // Three of four steps turn the kept matrices (a step whose first matrix does not contract
    // tenfold computes them anew, and the count starts again).
    EXPECT_LT(r4.body_matrices_computed, r1.body_matrices_computed / 3);
    EXPECT_GE(r4.body_matrices_computed + r4.body_matrices_turned, r1.body_matrices_computed);
    // Only Newton's matrix differs: both runs converge to the same tolerance (1e-9 of the forces),
    // so the paths agree to that order of the travel (measured 1e-12 m of 0.30 m).
    EXPECT_LT(largest, 1e-9 * travel);
    // The lagging matrix costs some iterations (measured 1312 -> 1461), far fewer than it saves.
    EXPECT_LT(r4.newton_iterations, 1.5 * r1.newton_iterations);
  }
}

}  // namespace
}  // namespace femb
