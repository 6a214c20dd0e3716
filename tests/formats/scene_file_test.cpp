// Scene file parsing (formats/scene_file.h): what a good file gives, the time functions'
// values, rates and breakpoints against their closed forms, and one line naming the file, line and
// key for bad input.
#include "formats/scene_file.h"

#include <gtest/gtest.h>

#include <cmath>

#include "test_util.h"

namespace femb {
namespace {

const std::string kGood =
    "name: pendulum\n"                                                         // 1
    "bodies:\n"                                                                // 2
    "  - {name: rod, superelement: rod.h5, nodes: {A: pivot, B: tip}}\n"       // 3
    "joints:\n"                                                                // 4
    "  - {type: revolute, node: pivot, axis: [0, 0, 1], prescribed: drive}\n"  // 5
    "functions:\n"                                                             // 6
    "  drive: {type: ramp, value: 2.0, t_start: 0.1, t_end: 0.3}\n"            // 7
    "  push: {type: pulse, value: 5.0, t_start: 0.2, t_end: 0.25}\n"           // 8
    "  path: {type: table, points: [[0, 0], [1, 2], [3, 0]]}\n"                // 9
    "  spin: {type: spin_up, omega: 6.0, t_spin: 15.0}\n"                      // 10
    "loads:\n"                                                                 // 11
    "  - {type: force, node: tip, force: [0, 1, 0], function: push}\n"         // 12
    "analysis:\n"                                                              // 13
    "  type: dynamic\n"                                                        // 14
    "  end_time: 1.0\n"                                                        // 15
    "  step: 1.0e-3\n"                                                         // 16
    "  integrator: midpoint\n";                                                // 17

using test::Replace;

std::string Error(const std::string& text, const std::vector<std::string>& overrides = {}) {
  return test::ThrownMessage([&] { ParseScene(text, "scene.yaml", overrides); });
}

TEST(SceneFile, GoodFileParses) {
  const SceneSpec s = ParseScene(kGood, "scene.yaml");
  EXPECT_EQ(s.name, "pendulum");
  ASSERT_EQ(s.bodies.size(), 1u);
  EXPECT_EQ(s.bodies[0].nodes.at("B"), "tip");
  ASSERT_EQ(s.joints.size(), 1u);
  EXPECT_EQ(s.joints[0].prescribed, "drive");
  EXPECT_EQ(s.analysis.type, AnalysisType::kDynamic);
  EXPECT_EQ(s.analysis.integrator, Integrator::kMidpoint);
  EXPECT_DOUBLE_EQ(s.analysis.step, 1e-3);
  EXPECT_FALSE(s.analysis.adaptive_step);
  EXPECT_EQ(s.functions.at("spin").type, TimeFunctionType::kSpinUp);
}

TEST(SceneFile, StepAutoAndItsLimits) {
  const SceneSpec s = ParseScene(kGood, "scene.yaml",
                                 {"analysis.step=auto", "analysis.step_tolerance=1e-6", "analysis.min_step=1e-8",
                                  "analysis.max_step=1e-2", "analysis.output_step=5e-3"});
  EXPECT_TRUE(s.analysis.adaptive_step);
  EXPECT_DOUBLE_EQ(s.analysis.step_tolerance, 1e-6);
  EXPECT_DOUBLE_EQ(s.analysis.min_step, 1e-8);
  EXPECT_DOUBLE_EQ(s.analysis.max_step, 1e-2);
  EXPECT_DOUBLE_EQ(s.analysis.output_step, 5e-3);
  EXPECT_DOUBLE_EQ(ParseScene(kGood, "scene.yaml", {"analysis.step=auto"}).analysis.step_tolerance, 1e-5);
}

TEST(SceneFile, BodyMatricesEveryIsAWholeNumberOfSteps) {
  EXPECT_EQ(ParseScene(kGood, "scene.yaml").analysis.body_matrices_every, 0);  // unset: the solver's default
  EXPECT_EQ(ParseScene(kGood, "scene.yaml", {"analysis.body_matrices_every=3"}).analysis.body_matrices_every, 3);
  for (const char* bad : {"0", "-2", "1.5", "often"}) {
    const std::string message = Error(kGood, {std::string("analysis.body_matrices_every=") + bad});
    EXPECT_NE(message.find("body_matrices_every"), std::string::npos) << bad << ": " << message;
  }
}

TEST(SceneFile, BodyMatricesKeptIsInertiaOrAll) {
  EXPECT_EQ(ParseScene(kGood, "scene.yaml").analysis.body_matrices_kept, BodyMatricesKept::kAll);
  EXPECT_EQ(ParseScene(kGood, "scene.yaml", {"analysis.body_matrices_kept=inertia"}).analysis.body_matrices_kept,
            BodyMatricesKept::kInertia);
  EXPECT_EQ(ParseScene(kGood, "scene.yaml", {"analysis.body_matrices_kept=all"}).analysis.body_matrices_kept,
            BodyMatricesKept::kAll);
  const std::string message = Error(kGood, {"analysis.body_matrices_kept=mass"});
  EXPECT_NE(message.find("body_matrices_kept"), std::string::npos) << message;
}

TEST(SceneFile, JacobianReuseTakesItsNamesAndTheOldBooleans) {
  const auto reuse = [](const std::string& value) {
    return ParseScene(kGood, "scene.yaml", {"analysis.jacobian_reuse=" + value}).analysis.jacobian_reuse;
  };
  EXPECT_FALSE(ParseScene(kGood, "scene.yaml").analysis.jacobian_reuse.has_value());
  EXPECT_EQ(reuse("step"), JacobianReuse::kStep);
  EXPECT_EQ(reuse("steps"), JacobianReuse::kSteps);
  EXPECT_EQ(reuse("none"), JacobianReuse::kNone);
  EXPECT_EQ(reuse("true"), JacobianReuse::kSteps);  // the boolean's meaning before `step`
  EXPECT_EQ(reuse("false"), JacobianReuse::kNone);
  const std::string bad = Error(kGood, {"analysis.jacobian_reuse=sometimes"});
  EXPECT_NE(bad.find("jacobian_reuse"), std::string::npos) << bad;
  EXPECT_NE(bad.find("expected step, steps, none, true or false, got 'sometimes'"), std::string::npos) << bad;
}

TEST(SceneFile, RadauTakesFixedAndErrorControlledSteps) {
  EXPECT_EQ(ParseScene(kGood, "scene.yaml", {"analysis.integrator=radau"}).analysis.integrator, Integrator::kRadau);
  const SceneSpec automatic = ParseScene(kGood, "scene.yaml", {"analysis.integrator=radau", "analysis.step=auto"});
  EXPECT_EQ(automatic.analysis.integrator, Integrator::kRadau);
  EXPECT_TRUE(automatic.analysis.adaptive_step);
}

TEST(SceneFile, TimeFunctionsFollowTheirClosedForms) {
  const SceneSpec s = ParseScene(kGood, "scene.yaml");
  const TimeFunctionSpec& ramp = s.functions.at("drive");
  EXPECT_DOUBLE_EQ(ramp.Evaluate(0.05), 0.0);
  EXPECT_DOUBLE_EQ(ramp.Evaluate(0.2), 1.0);
  EXPECT_DOUBLE_EQ(ramp.Evaluate(0.5), 2.0);
  EXPECT_DOUBLE_EQ(ramp.Rate(0.2), 10.0);
  EXPECT_EQ(ramp.Breakpoints(), (std::vector<double>{0.1, 0.3}));
  const TimeFunctionSpec& pulse = s.functions.at("push");
  EXPECT_DOUBLE_EQ(pulse.Evaluate(0.2), 5.0);   // on from t_start
  EXPECT_DOUBLE_EQ(pulse.Evaluate(0.25), 0.0);  // off at t_end
  EXPECT_EQ(pulse.Breakpoints(), (std::vector<double>{0.2, 0.25}));
  const TimeFunctionSpec& table = s.functions.at("path");
  EXPECT_DOUBLE_EQ(table.Evaluate(0.5), 1.0);
  EXPECT_DOUBLE_EQ(table.Evaluate(2.0), 1.0);
  EXPECT_DOUBLE_EQ(table.Evaluate(5.0), 0.0);
  EXPECT_DOUBLE_EQ(table.Rate(2.0), -1.0);
  EXPECT_EQ(table.Breakpoints(), (std::vector<double>{0, 1, 3}));
  // Spin-up: theta = (w/Ts)(t^2/2 + (Ts/2pi)^2 (cos(2 pi t/Ts) - 1)); rate and acceleration
  // against central differences; after Ts a constant rate w.
  const TimeFunctionSpec& spin = s.functions.at("spin");
  const double h = 1e-4;
  for (double t : {1.0, 7.5, 14.0}) {
    EXPECT_NEAR(spin.Rate(t), (spin.Evaluate(t + h) - spin.Evaluate(t - h)) / (2 * h), 1e-7);
    EXPECT_NEAR(spin.Acceleration(t), (spin.Rate(t + h) - spin.Rate(t - h)) / (2 * h), 1e-7);
  }
  EXPECT_DOUBLE_EQ(spin.Rate(20.0), 6.0);
  EXPECT_NEAR(spin.Evaluate(15.0), 6.0 * 7.5, 1e-12);  // continuous at Ts
  EXPECT_EQ(spin.Breakpoints(), (std::vector<double>{15.0}));
  const SceneSpec sine =
      ParseScene(kGood, "scene.yaml", {"functions.drive={type: sine, amplitude: 2, frequency: 0.5}"});
  EXPECT_NEAR(sine.functions.at("drive").Evaluate(0.5), 2.0, 1e-15);
  EXPECT_TRUE(sine.functions.at("drive").Breakpoints().empty());
}

TEST(SceneFile, BadInputNamesTheFileLineAndKey) {
  EXPECT_NE(Error(kGood, {"analysis.step=auto", "analysis.min_step=0.1", "analysis.max_step=0.01"})
                .find("min_step 0.1 is above max_step 0.01"),
            std::string::npos);
  // Values given with --set are named by their key.
  const std::string tolerance = Error(kGood, {"analysis.step_tolerance=-1"});
  EXPECT_NE(tolerance.find("--set analysis.step_tolerance: must be positive"), std::string::npos) << tolerance;
  const std::string step = Error(kGood, {"analysis.step=fast"});
  EXPECT_NE(step.find("--set analysis.step"), std::string::npos) << step;
  // Values in the file by file and line.
  const std::string function = Error(Replace(kGood, "type: pulse", "type: cosine"));
  EXPECT_NE(function.find("scene.yaml:8"), std::string::npos) << function;
  EXPECT_NE(function.find("unknown time function type 'cosine'"), std::string::npos) << function;
  const std::string type = Error(Replace(kGood, "type: dynamic", "type: transient"));
  EXPECT_NE(type.find("scene.yaml:14"), std::string::npos) << type;
  EXPECT_NE(type.find("unknown analysis type 'transient'"), std::string::npos) << type;
  const std::string ramp = Error(kGood, {"functions.drive.t_end=0.05"});
  EXPECT_NE(ramp.find("t_end must be after t_start"), std::string::npos) << ramp;
  const std::string rho = Error(kGood, {"analysis.rho_inf=1.5"});
  EXPECT_NE(rho.find("rho_inf must be in [0, 1]"), std::string::npos) << rho;
  const std::string node = Error(kGood, {"loads[0].node=nowhere"});
  EXPECT_NE(node.find("node 'nowhere' is not a node of any body"), std::string::npos) << node;
}

}  // namespace
}  // namespace femb
