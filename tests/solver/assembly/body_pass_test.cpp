// The one pass over the bodies (solver/assembly/body_pass.h) that statics and the dynamic
// integrators share, on the slider-crank of test::SliderCrankModel (a tube crank driven about
// its pivot, a rod of two bodies, the slider on a prismatic joint: a tree, no multipliers;
// gravity) with stiffened bodies (exact inertia, inertia stiffening):
//  - statics is the dynamic pass at rest: at W = Wdot = 0 the inertia force vanishes, and the
//    static residual at full weight equals the dynamic one, the node forces too (to 1e-14 of the
//    force scale; the sums differ in order: statics keeps the weight with the loads);
//  - the static pass gives the same bits on 1 and 2 threads, with and without a kept workspace;
//  - the reactions an output reads from the converged pass (statics' StaticStepReport, the
//    generalized-alpha step's DynamicStepReport) equal those of an assembly at the same state
//    (to 1e-12 of the largest reaction: the assembly solves the frames again from the converged
//    ones).
#include "solver/assembly/body_pass.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <vector>

#include "solver/analysis/dynamic_analysis.h"
#include "solver/analysis/dynamic_step.h"
#include "solver/analysis/static_analysis.h"
#include "solver/parallel.h"
#include "tests/test_util.h"

namespace femb {
namespace {

using Vec6 = Eigen::Matrix<double, 6, 1>;

SystemModel Model() {
  Superelement rod = test::TubeSegment(0.25, 8, true);
  Superelement crank = test::TubeSegment(0.15, 6, true);
  SystemModel model = test::SliderCrankModel(crank, rod, 0.15, 0.25);
  model.static_gravity_end = 1.0;  // statics: the weight in full from pseudo-time 1
  return model;
}

// The model's placement moved by a small increment on every solved unknown (the bodies deformed).
SystemState Deformed(const SystemModel& model) {
  const DofMap& dofs = model.dofs();
  SystemState state = InitialState(model);
  Eigen::VectorXd delta = Eigen::VectorXd::Zero(dofs.n_dofs());
  for (int j : dofs.solved()) delta[j] = 1e-3 * std::sin(1.7 * j + 0.3);
  ApplyIncrement(model, dofs, delta, state);
  return state;
}

double Largest(const std::vector<Vec6>& a) {
  double m = 0.0;
  for (const Vec6& v : a) m = std::max(m, v.cwiseAbs().maxCoeff());
  return m;
}

double LargestDifference(const std::vector<Vec6>& a, const std::vector<Vec6>& b) {
  EXPECT_EQ(a.size(), b.size());
  double m = 0.0;
  for (size_t k = 0; k < std::min(a.size(), b.size()); ++k) m = std::max(m, (a[k] - b[k]).cwiseAbs().maxCoeff());
  return m;
}

TEST(BodyPass, StaticsIsTheDynamicPassAtRest) {
  const SystemModel model = Model();
  const DofMap& dofs = model.dofs();
  const SystemState state = Deformed(model);
  SystemState at_rest = state;
  const SystemForces f = AssembleStatic(model, dofs, at_rest, 1.0, false);
  ASSERT_TRUE(f.ok) << f.message;
  DynamicState s;
  s.config = state;
  s.W = Eigen::VectorXd::Zero(dofs.n_dofs());
  s.Wdot = Eigen::VectorXd::Zero(dofs.n_dofs());
  const Assembly a = dynamic_internal::AssembleDynamic(model, dofs, s, 1.0, false);
  ASSERT_TRUE(a.ok) << a.message;
  const double scale = f.residual.cwiseAbs().maxCoeff() + f.loads.cwiseAbs().maxCoeff();
  ASSERT_GT(f.loads.norm(), 0.0);                       // the weight is in
  ASSERT_GT(f.residual.norm(), 1e-3 * f.loads.norm());  // and the deformed bodies push back
  EXPECT_LE((f.residual - a.residual).cwiseAbs().maxCoeff(), 1e-14 * scale);
  EXPECT_LE((f.loads - a.f_ext).cwiseAbs().maxCoeff(), 1e-14 * scale);
  EXPECT_LE(LargestDifference(f.node_forces.f, a.node_forces.f), 1e-14 * Largest(f.node_forces.f));
}

TEST(BodyPass, StaticPassGivesTheSameBitsOnAnyThreadsAndWorkspace) {
  const SystemModel model = Model();
  const DofMap& dofs = model.dofs();
  SystemState plain = Deformed(model);
  const SystemForces f1 = AssembleStatic(model, dofs, plain, 0.7, true);
  ASSERT_TRUE(f1.ok) << f1.message;
  StaticWorkspace work;
  BodyThreads pool(2);
  for (int call = 0; call < 2; ++call) {  // the second call in the kept storage
    SystemState threaded = Deformed(model);
    const SystemForces f2 = AssembleStatic(model, dofs, threaded, 0.7, true, &work, &pool);
    ASSERT_TRUE(f2.ok) << f2.message;
    EXPECT_EQ((f1.residual - f2.residual).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ((Eigen::MatrixXd(f1.tangent) - Eigen::MatrixXd(f2.tangent)).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ(LargestDifference(f1.node_forces.f, f2.node_forces.f), 0.0);
    EXPECT_EQ(f1.elastic_energy, f2.elastic_energy);
    EXPECT_EQ(f1.force_scale, f2.force_scale);
    EXPECT_EQ((f1.dof_scale - f2.dof_scale).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ(f1.roundoff, f2.roundoff);
  }
}

TEST(BodyPass, StaticReactionsReadTheConvergedPass) {
  const SystemModel model = Model();
  const DofMap& dofs = model.dofs();
  SystemState state = InitialState(model);
  StaticOptions options;
  options.end_time = 1.0;
  options.steps = 4;
  options.threads = 2;
  int compared = 0;
  const StaticResult r = SolveStatic(model, state, options, [&](const StaticStepReport& s, const SystemState& st) {
    ASSERT_NE(s.node_forces, nullptr);
    const std::vector<Vec6> from_pass = JointReactions(model, dofs, st, *s.node_forces);
    SystemState copy = st;
    const SystemForces f = AssembleStatic(model, dofs, copy, s.lambda, false);
    const std::vector<Vec6> assembled = JointReactions(model, dofs, copy, f.node_forces);
    ASSERT_GT(Largest(assembled), 0.0);
    EXPECT_LE(LargestDifference(from_pass, assembled), 1e-12 * Largest(assembled)) << "at " << s.lambda;
    ++compared;
  });
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_EQ(compared, 4);
}

TEST(BodyPass, DynamicReactionsReadTheConvergedGeneralizedAlphaPass) {
  const SystemModel model = Model();
  const DofMap& dofs = model.dofs();
  for (const Integrator integrator : {Integrator::kGeneralizedAlpha, Integrator::kMidpoint}) {
    DynamicState s = InitialDynamicState(model, InitialState(model), Eigen::VectorXd::Zero(dofs.n_dofs()));
    DynamicOptions options;
    options.integrator = integrator;
    options.step = 1e-4;
    options.end_time = 0.004;
    options.threads = 2;
    int compared = 0, without = 0;
    const DynamicResult r = SolveDynamic(model, s, options, [&](const DynamicStepReport& rep, const DynamicState& st) {
      if (!rep.node_forces) {
        ++without;
        return;
      }
      const std::vector<Vec6> from_pass = JointReactions(model, dofs, st.config, *rep.node_forces);
      const std::vector<Vec6> assembled = DynamicReactions(model, st);
      ASSERT_GT(Largest(assembled), 0.0);
      EXPECT_LE(LargestDifference(from_pass, assembled), 1e-12 * Largest(assembled)) << "at t = " << rep.t;
      ++compared;
    });
    ASSERT_TRUE(r.ok) << r.message;
    if (integrator == Integrator::kGeneralizedAlpha) {
      EXPECT_EQ(compared, 40);
    } else {
      // The midpoint scheme's pass is at the step's mid configuration: the reactions assemble.
      EXPECT_EQ(without, 40);
    }
  }
}

}  // namespace
}  // namespace femb
