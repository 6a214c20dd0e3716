// StepController (solver/analysis/step_control.h) on its own: where steps land, and the error
// estimate against its closed form for a coordinate whose acceleration is known.
#include "solver/analysis/step_control.h"

#include <gtest/gtest.h>

#include <cmath>

namespace femb {
namespace {

// Two free nodes 1 m apart: 12 coordinates, translations weighted 1 (lengths as they are).
SystemModel TwoNodes() {
  SystemModel model;
  AddNode(model, "a", Eigen::Vector3d::Zero());
  AddNode(model, "b", Eigen::Vector3d(1, 0, 0));
  model.Number();
  return model;
}

// Error-controlled steps from 0 to end_time: the first step tried and the largest.
DynamicOptions Steps(double end_time, double step, double max_step) {
  DynamicOptions options;
  options.adaptive = true;
  options.end_time = end_time;
  options.step = step;
  options.max_step = max_step;
  return options;
}

// Each stretch to the next boundary in equal steps of at most the step asked for (no Accept
// here: every Fit plans anew).
TEST(StepControl, StepsLandOnTheEndBreakpointsAndOutputTimes) {
  const SystemModel model = TwoNodes();
  const DofMap dofs(model);
  DynamicOptions options = Steps(1.0, 0.05, 0.2);
  options.breakpoints = {0.25, 0.7};
  StepController c(model, dofs, options, 0.0);
  EXPECT_DOUBLE_EQ(c.FirstStep(), 0.05);
  EXPECT_DOUBLE_EQ(c.Fit(0.0, 0.1), 0.25 / 3);  // three equal steps to the breakpoint
  EXPECT_FALSE(c.lands());
  EXPECT_DOUBLE_EQ(c.Fit(0.2, 0.1), 0.05);  // lands on the breakpoint
  EXPECT_TRUE(c.at_breakpoint());
  EXPECT_DOUBLE_EQ(c.boundary(), 0.25);
  EXPECT_DOUBLE_EQ(c.Fit(0.25, 0.1), 0.09);   // the breakpoint it stands on is behind it: 5 steps to 0.7
  EXPECT_DOUBLE_EQ(c.Fit(0.55, 0.1), 0.075);  // two equal steps rather than a sliver
  EXPECT_FALSE(c.lands());
  EXPECT_DOUBLE_EQ(c.Fit(0.9, 0.5), 0.1);  // max_step, then the end
  EXPECT_TRUE(c.lands() && c.output() && !c.at_breakpoint());
  EXPECT_NEAR(c.Fit(0.8, 1e-12), c.min_step(), 1e-20);  // at least min_step (1e-8 of the span)
  EXPECT_DOUBLE_EQ(c.min_step(), 1e-8);

  options.output_step = 0.3;  // outputs at 0.3, 0.6, 0.9; a breakpoint is not an output
  StepController o(model, dofs, options, 0.0);
  EXPECT_DOUBLE_EQ(o.Fit(0.2, 0.1), 0.05);
  EXPECT_TRUE(o.at_breakpoint() && !o.output());
  EXPECT_DOUBLE_EQ(o.Fit(0.25, 0.1), 0.05);
  EXPECT_TRUE(o.output() && !o.at_breakpoint());
  EXPECT_DOUBLE_EQ(o.boundary(), 0.3);
}

// The plan is kept while the controller's proposal after an accepted step stays within [0.9,
// 1.25] of the step in use, or until 7 steps have passed since it was made; it is made anew
// outside the band after that, and at once after a rejection.
TEST(StepControl, TheStepChangesOnlyOutsideTheBandAndSeldom) {
  const SystemModel model = TwoNodes();
  const DofMap dofs(model);
  const DynamicOptions options = Steps(10.0, 0.1, 0.2);
  StepController c(model, dofs, options, 0.0);
  const DynamicState s = InitialDynamicState(model, InitialState(model), Eigen::VectorXd::Zero(dofs.n_dofs()));
  EXPECT_DOUBLE_EQ(c.Fit(0.0, 0.1), 0.1);
  const double slightly_less = c.Accept(s, 0.1, 1.0, false);  // 0.9 E^(-1/3): 0.09
  EXPECT_DOUBLE_EQ(slightly_less, 0.09);
  EXPECT_DOUBLE_EQ(c.Fit(0.1, slightly_less), 0.1);  // within the band: kept
  double t = 0.2;
  for (int k = 2; k <= 7; ++k, t += 0.1) {
    const double much_more = c.Accept(s, 0.1, 0.01, false);
    EXPECT_GT(much_more, 0.125);
    const double rest = 10.0 - t, expected = k < 7 ? 0.1 : rest / std::ceil(rest / much_more - 1e-6);
    EXPECT_NEAR(c.Fit(t, much_more), expected, 1e-12) << "proposal " << k;  // made anew after the 7th
  }
  EXPECT_NEAR(c.Fit(t, 0.095), (10.0 - t) / std::ceil((10.0 - t) / 0.095 - 1e-6), 1e-12);  // a retry: at once
}

// Node b's x accelerates linearly in time (jerk j): generalized-alpha's estimate is
// |1/6 - beta - (alpha_m - alpha_f)/2| h^3 j against step_tolerance times the largest travel
// (at start 1e-3 of the model's size, 1 mm here).
TEST(StepControl, ErrorEstimateIsTheLocalErrorOfAConstantJerk) {
  const SystemModel model = TwoNodes();
  const DofMap dofs(model);
  DynamicOptions options;
  options.end_time = 1.0;
  options.rho_inf = 0.8;
  options.step_tolerance = 1e-4;
  StepController c(model, dofs, options, 0.0);
  const int n = dofs.n_dofs();
  DynamicState s0, s1;
  s0.Wdot = s1.Wdot = s0.a = s1.a = Eigen::VectorXd::Zero(n);
  const double h = 1e-2, jerk = 3.0;
  const int x_b = dofs.node_first(1);
  s1.Wdot[x_b] = jerk * h;
  const double rho = 0.8, alpha_m = (2 * rho - 1) / (rho + 1), alpha_f = rho / (rho + 1);
  const double gamma = 0.5 + alpha_f - alpha_m, beta = 0.25 * (gamma + 0.5) * (gamma + 0.5);
  const double expected = std::abs(1.0 / 6 - beta - 0.5 * (alpha_m - alpha_f)) * h * h * h * jerk / (1e-4 * 1e-3);
  EXPECT_NEAR(c.Error(s0, s1, h), expected, 1e-12 * expected);
  // Error ratio 1 after a rejection: no growth; E = 1/8 with no history: twice the step, at most.
  EXPECT_NEAR(StepController::Factor(1.0), 0.9, 1e-15);
  EXPECT_DOUBLE_EQ(StepController::Factor(1.0 / 8), 1.8);
  EXPECT_DOUBLE_EQ(StepController::Factor(0.0), 2.0);
  EXPECT_DOUBLE_EQ(StepController::Factor(1e6), 0.2);
}

}  // namespace
}  // namespace femb
