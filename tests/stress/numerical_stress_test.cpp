// Numerical stress tests: each case states its reference and its pass criterion; the
// README's "Numerical stress tests" table summarizes them. Scenes are built from text and
// superelements reduced in memory, then solved through the library as femb-solve does.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <tuple>

#include "formats/scene_file.h"
#include "formats/superelement_file.h"
#include "solver/analysis/dynamic_analysis.h"
#include "solver/analysis/static_analysis.h"
#include "solver/scene/scene_builder.h"
#include "test_util.h"

namespace femb {
namespace {

// A steel rod (d = 6 mm) of length L [m], in SI or mm-t-s, with `modes` internal modes.
std::string RodYaml(double L, int modes, bool mm, double E_factor = 1.0, double rho_factor = 1.0) {
  const double s = mm ? 1000.0 : 1.0;  // length unit per metre
  char text[1024];
  std::snprintf(
      text, sizeof text,
      "name: rod\ntype: beam\nunits: %s\nmaterial: {E: %.17g, nu: 0.3, rho: %.17g}\n"
      "section: {shape: circle, diameter: %.17g}\n"
      "beam:\n  points: {A: [0, 0, 0], B: [%.17g, 0, 0]}\n  segments: [{from: A, to: B, elements: 12}]\n"
      "interfaces: [{name: A}, {name: B}]\nreduction: {internal_modes: %d, floating_frame: center_of_mass}\n%s",
      mm ? "mm-t-s" : "SI", 2e11 * E_factor / (mm ? 1e6 : 1.0), 7870.0 * rho_factor / (mm ? 1e12 : 1.0), 0.006 * s,
      L * s, modes, E_factor != 1.0 || rho_factor != 1.0 ? "check_units: false\n" : "");
  return text;
}

struct Outcome {
  bool ok = false;
  std::string message;
  std::vector<std::string> warnings;
  std::vector<double> t;
  std::vector<Eigen::Vector3d> tip;    ///< position of the probe node (relative to origin)
  Eigen::Vector3d origin;              ///< the scene's computing origin (scene_builder.h)
  std::vector<double> energy_balance;  ///< T + U - W_loads - W_drives
  long steps = 0;
};

// Writes the superelements into a fresh folder, builds the scene from `scene` (YAML) and runs
// its analysis; `tip` names the node recorded.
Outcome Simulate(const std::string& name, const std::string& scene, const std::map<std::string, Superelement>& files,
                 const std::string& tip, const std::function<void(DynamicOptions&)>& tweak = nullptr) {
  const std::string dir = ::testing::TempDir() + "stress_" + name;
  std::filesystem::create_directories(dir);
  for (const auto& [file, se] : files) WriteSuperelementFile(se, dir + "/" + file);
  const Scene s = BuildScene(ParseScene(scene, dir + "/scene.yaml"));
  const int node = s.node_index.at(tip);
  Outcome run;
  run.origin = s.origin;
  const SceneAnalysisSpec& a = s.spec.analysis;
  if (a.type == AnalysisType::kStatic) {
    SystemState state = InitialState(s.model);
    StaticOptions options;
    options.end_time = a.end_time;
    options.steps = a.steps;
    options.tolerance = a.tolerance;
    const StaticResult r =
        SolveStatic(s.model, state, options, [&](const StaticStepReport& step, const SystemState& st) {
          run.t.push_back(step.lambda);
          run.tip.push_back(st.x[node]);
        });
    run.ok = r.ok;
    run.message = r.message;
    run.warnings = r.warnings;
    run.steps = long(r.steps.size());
    return run;
  }
  DynamicState state = InitialDynamicState(s.model, InitialState(s.model), s.initial_velocity);
  DynamicOptions options;
  options.step = a.step;
  options.end_time = a.end_time;
  options.rho_inf = a.rho_inf;
  options.tolerance = a.tolerance;
  options.integrator = a.integrator;
  if (tweak) tweak(options);
  const DynamicStepReport r0 = Measure(s.model, state);
  const double E0 = r0.kinetic_energy + r0.elastic_energy;
  const DynamicResult r =
      SolveDynamic(s.model, state, options, [&](const DynamicStepReport& step, const DynamicState& st) {
        run.t.push_back(step.t);
        run.tip.push_back(st.config.x[node]);
        run.energy_balance.push_back(step.kinetic_energy + step.elastic_energy - step.external_work - st.drive_work -
                                     E0);
      });
  run.ok = r.ok;
  run.message = r.message;
  run.warnings = r.warnings;
  run.steps = r.steps;
  return run;
}

// A flexible rod pendulum (revolute joint about z at A), released 0.5 rad from hanging, with a
// rigid block hanging from its tip on a spherical joint: 1 s. Placed at `origin` [m].
std::string Pendulum(bool mm, const Eigen::Vector3d& origin, const std::string& analysis) {
  const double s = mm ? 1000.0 : 1.0;
  char text[2048];
  std::snprintf(
      text, sizeof text,
      "name: pendulum\nunits: %s\n"
      "bodies:\n"
      "  - {name: rod, superelement: rod.h5, placement: {position: [%.17g, %.17g, %.17g], rotation: [0, 0, "
      "-1.0707963267948966]}, nodes: {A: pivot, B: tip}}\n"
      "  - {name: block, type: rigid, mass: %.17g, center_of_mass: [0, %.17g, 0], inertia: [%.17g, %.17g, %.17g],\n"
      "     points: {P: [0, 0, 0]}, placement: {position: [%.17g, %.17g, %.17g]}, nodes: {P: tip}}\n"
      "joints:\n  - {type: revolute, node: pivot, axis: [0, 0, 1]}\n"
      "loads:\n  - {type: gravity, g: [0, %.17g, 0]}\n"
      "analysis: %s\n",
      mm ? "mm-t-s" : "SI", origin.x() * s, origin.y() * s, origin.z() * s, 0.05 / (mm ? 1000.0 : 1.0), -0.02 * s,
      1e-5 * (mm ? 1e3 : 1.0), 1e-5 * (mm ? 1e3 : 1.0), 1e-5 * (mm ? 1e3 : 1.0),
      (origin.x() + 0.3 * std::cos(-1.0707963267948966)) * s, (origin.y() + 0.3 * std::sin(-1.0707963267948966)) * s,
      origin.z() * s, -9.81 * s, analysis.c_str());
  return text;
}

// A straight chain of n bodies of `seg.h5` (length `segment` each) along x, nodes n0..n<n>,
// clamped at n0.
std::string ClampedChain(const std::string& name, int n, double segment) {
  std::string scene = "name: " + name + "\nunits: SI\nbodies:\n";
  for (int b = 0; b < n; ++b) {
    char line[200];
    std::snprintf(line, sizeof line,
                  "  - {name: b%d, superelement: seg.h5, placement: {position: [%g, 0, 0]}, nodes: {A: n%d, B: n%d}}\n",
                  b, segment * b, b, b + 1);
    scene += line;
  }
  return scene + "joints:\n  - {type: clamp, node: n0}\n";
}

double Amplitude(const Outcome& r, const Eigen::Vector3d& centre) {
  double a = 0.0;
  for (const Eigen::Vector3d& x : r.tip) a = std::max(a, (x - centre).norm());
  return a;
}

// Units: the same pendulum in SI and in mm-t-s gives the same tip history after conversion.
// Reference: the SI run. Criterion: max |x_mm / 1000 - x_SI| <= 1e-10 of the swing radius
// (Newton's residual is weighted to forces in any unit system, system.h ResidualWeights; when it
// mixed forces with moments, 1000x larger numbers in N mm, the runs differed by 1.5e-6).
TEST(NumericalStress, SameModelInSiAndMillimetresAgrees) {
  const std::string analysis = "{type: dynamic, end_time: 1.0, step: 1e-3, rho_inf: 0.9}";
  const Outcome si = Simulate("si", Pendulum(false, Eigen::Vector3d::Zero(), analysis),
                              {{"rod.h5", test::Reduce(RodYaml(0.3, 2, false))}}, "tip");
  const Outcome mm = Simulate("mm", Pendulum(true, Eigen::Vector3d::Zero(), analysis),
                              {{"rod.h5", test::Reduce(RodYaml(0.3, 2, true))}}, "tip");
  ASSERT_TRUE(si.ok) << si.message;
  ASSERT_TRUE(mm.ok) << mm.message;
  ASSERT_EQ(si.tip.size(), mm.tip.size());
  double worst = 0.0;
  for (size_t k = 0; k < si.tip.size(); ++k) worst = std::max(worst, (mm.tip[k] / 1000.0 - si.tip[k]).norm());
  const double radius = Amplitude(si, Eigen::Vector3d::Zero());
  std::printf("[ info ] SI vs mm-t-s: largest tip difference %.3g of the swing radius %.3g m\n", worst / radius,
              radius);
  EXPECT_LT(worst / radius, 1e-10);
}

// Far from the origin: the pendulum 1e4 m away gives the same motion (shifted). Criterion:
// max |x_far - offset - x_origin| <= 1e-6 of the swing radius.
TEST(NumericalStress, ModelFarFromTheOriginAgrees) {
  const std::string analysis = "{type: dynamic, end_time: 1.0, step: 1e-3, rho_inf: 0.9}";
  const Superelement rod = test::Reduce(RodYaml(0.3, 2, false));
  const Eigen::Vector3d far(1e4, -1e4, 1e4);
  const Outcome near_run =
      Simulate("near", Pendulum(false, Eigen::Vector3d::Zero(), analysis), {{"rod.h5", rod}}, "tip");
  const Outcome far_run = Simulate("far", Pendulum(false, far, analysis), {{"rod.h5", rod}}, "tip");
  ASSERT_TRUE(near_run.ok) << near_run.message;
  ASSERT_TRUE(far_run.ok) << far_run.message;
  ASSERT_EQ(near_run.tip.size(), far_run.tip.size());
  double worst = 0.0;
  for (size_t k = 0; k < near_run.tip.size(); ++k) {
    worst = std::max(worst, ((far_run.origin + far_run.tip[k]) - far - (near_run.origin + near_run.tip[k])).norm());
  }
  const double radius = Amplitude(near_run, Eigen::Vector3d::Zero());
  std::printf("[ info ] 1e4 m from the origin: largest difference %.3g of the swing radius\n", worst / radius);
  EXPECT_LT(worst / radius, 1e-6);
}

// Conservative flexible system over 1e5 steps (the pendulum without its block, 2 modes, h = 1e-4
// s, 10 s): the energy balance error stays bounded and does not grow. Midpoint and
// generalized-alpha with rho_inf = 1. Criterion: |E error| <= 1e-3 of the swing's energy, and the
// largest error over the last quarter <= 1.5x the largest over the first quarter, or both below
// 1e-6 of it (the midpoint scheme's error is 1e-8: round-off).
TEST(NumericalStress, ConservativeFlexibleSystemOver1e5StepsKeepsItsEnergy) {
  const Superelement rod = test::Reduce(RodYaml(0.3, 2, false));
  const std::string scene =
      "name: swing\nunits: SI\nbodies:\n"
      "  - {name: rod, superelement: rod.h5, placement: {rotation: [0, 0, -1.0707963267948966]}, nodes: {A: pivot, B: "
      "tip}}\n"
      "joints:\n  - {type: revolute, node: pivot, axis: [0, 0, 1]}\nloads:\n  - {type: gravity, g: [0, -9.81, 0]}\n";
  for (const std::string integrator : {"midpoint", "generalized_alpha"}) {
    const Outcome r = Simulate(
        "swing_" + integrator,
        scene + "analysis: {type: dynamic, end_time: 10.0, step: 1e-4, rho_inf: 1.0, integrator: " + integrator + "}\n",
        {{"rod.h5", rod}}, "tip");
    ASSERT_TRUE(r.ok) << integrator << ": " << r.message;
    ASSERT_EQ(r.steps, 100000);
    const double swing = 0.0556 * 9.81 * 0.15 * (1 - std::cos(0.5));  // m g (L/2)(1 - cos 0.5)
    const size_t q = r.energy_balance.size() / 4;
    double first = 0.0, last = 0.0, worst = 0.0;
    for (size_t k = 0; k < r.energy_balance.size(); ++k) {
      const double e = std::abs(r.energy_balance[k]);
      worst = std::max(worst, e);
      if (k < q) first = std::max(first, e);
      if (k >= 3 * q) last = std::max(last, e);
    }
    std::printf("[ info ] %s, 1e5 steps: energy error max %.3g of the swing energy; first quarter %.3g, last %.3g\n",
                integrator.c_str(), worst / swing, first / swing, last / swing);
    EXPECT_LT(worst / swing, 1e-3) << integrator;
    EXPECT_LE(last, 1.5 * first + 1e-6 * swing) << integrator;
  }
}

// The swing's energy of the hinged rod released 0.5 rad from the vertical, m g (L/2)(1 - cos 0.5),
// and a run's largest energy growth (the largest of T + U - W_loads - W_drives).
double SwingEnergy() { return 0.0556 * 9.81 * 0.15 * (1 - std::cos(0.5)); }

double LargestGrowth(const Outcome& r) {
  double growth = -HUGE_VAL;
  for (double e : r.energy_balance) growth = std::max(growth, e);
  return growth;
}

// The rod of the stiff-mode tests hinged at its end and released 0.5 rad from the vertical under
// gravity, and their step: 10 periods of its highest mode f_max, at least 1 ms.
double LongStep(double f_max) { return 10.0 / f_max > 1e-3 ? 10.0 / f_max : 1e-3; }

std::string StiffRodScene() {
  return "name: stiff\nunits: SI\nbodies:\n"
         "  - {name: rod, superelement: rod.h5, placement: {rotation: [0, 0, -1.0707963267948966]}, nodes: {A: "
         "pivot, B: tip}}\n"
         "joints:\n  - {type: revolute, node: pivot, axis: [0, 0, 1]}\nloads:\n  - {type: gravity, g: [0, -9.81, "
         "0]}\n";
}

// Stiff modes and a long step: the rod with 40 internal modes (highest fixed-interface mode
// ~ 100 kHz) at h = 10 highest periods... and longer: h = 1 ms. With rho_inf = 0.5 the run is
// stable (energy does not grow: numerical damping removes the unresolved modes); with rho_inf = 1
// femb either stays stable or stops with the energy-growth message, never ends "completed" with
// a wrong energy.
TEST(NumericalStress, FortyModesAtALongStepAreStableOrStopped) {
  const Superelement rod = test::Reduce(RodYaml(0.3, 40, false));
  const double f_max = rod.internal_frequencies_hz.maxCoeff();
  const double h = LongStep(f_max);
  std::printf("[ info ] 40 modes: highest %.4g Hz, h = %.3g s = %.0f highest periods\n", f_max, h, h * f_max);
  const std::string scene = StiffRodScene();
  char analysis[200];
  std::snprintf(analysis, sizeof analysis, "analysis: {type: dynamic, end_time: 2.0, step: %.17g, rho_inf: 0.5}\n", h);
  const Outcome damped = Simulate("stiff_05", scene + analysis, {{"rod.h5", rod}}, "tip");
  ASSERT_TRUE(damped.ok) << damped.message;
  const double swing = SwingEnergy();
  const double growth = LargestGrowth(damped);
  std::printf("[ info ] rho_inf 0.5: largest energy growth %.3g of the swing energy\n", growth / swing);
  EXPECT_LT(growth, 1e-2 * swing) << "rho_inf 0.5: the energy grew";
  std::snprintf(analysis, sizeof analysis, "analysis: {type: dynamic, end_time: 2.0, step: %.17g, rho_inf: 1.0}\n", h);
  const Outcome undamped = Simulate("stiff_10", scene + analysis, {{"rod.h5", rod}}, "tip");
  if (undamped.ok) {
    const double g = LargestGrowth(undamped);
    std::printf("[ info ] rho_inf 1: completed, largest energy growth %.3g of the swing energy\n", g / swing);
    EXPECT_LT(g, 0.25 * swing) << "rho_inf 1: completed with an energy growth above the stop limit";
  } else {
    std::printf("[ info ] rho_inf 1: stopped: %s\n", undamped.message.c_str());
    EXPECT_NE(undamped.message.find("numerically unstable"), std::string::npos) << undamped.message;
  }
}

// The same rod and step under Radau IIA, which is L-stable: its stability function vanishes at
// infinity, so the modes h leaves unresolved are damped within a step and the run completes with
// no energy growth (nothing to set, no rho_inf).
TEST(NumericalStress, FortyModesAtALongStepRadauIsStable) {
  const Superelement rod = test::Reduce(RodYaml(0.3, 40, false));
  const double f_max = rod.internal_frequencies_hz.maxCoeff();
  const double h = LongStep(f_max);
  const std::string scene = StiffRodScene();
  char analysis[200];
  std::snprintf(analysis, sizeof analysis, "analysis: {type: dynamic, end_time: 2.0, step: %.17g, integrator: radau}\n",
                h);
  const Outcome r = Simulate("stiff_radau", scene + analysis, {{"rod.h5", rod}}, "tip");
  ASSERT_TRUE(r.ok) << r.message;
  const double swing = SwingEnergy();
  const double growth = LargestGrowth(r);
  std::printf(
      "[ info ] Radau IIA, 40 modes at h = %.3g s (%.0f highest periods): %ld steps, largest energy growth %.3g "
      "of the swing energy\n",
      h, h * f_max, r.steps, growth / swing);
  EXPECT_LT(growth, 1e-2 * swing) << "Radau IIA: the energy grew";
}

// Stiffness contrast 1e6 and mass ratio 1e5 between two rods sharing a node (a clamped soft rod
// carrying a stiff heavy one): the static tip deflection under a tip force matches beam theory
// for the two segments in series, and the dynamic run is stable.
// Reference: tip deflection of a stepped cantilever, P (L1^3 + 3 L1^2 L2 + 3 L1 L2^2) / 3EI_1 +
// P L2^3 / 3 EI_2 (EI_2 = 1e6 EI_1); criterion 1e-3 (shear deformation of the rods: d/L = 0.02).
// Linear bodies: the heavy rod's weight bends the soft one by 30 degrees inside one body, where
// the geometric stiffening's basis-stress force (the geometric stiffness form, not the gradient
// of the stored cubic energy: formats/reduced_polynomial.h) leaves an energy balance of 2% of the
// kinetic energy, independent of the step, which is the model's and not the integrator's.
TEST(NumericalStress, StiffnessAndMassContrastBetweenBodies) {
  const std::vector<std::string> linear = {"reduction.geometric_stiffening=false"};
  const Superelement soft = test::Reduce(RodYaml(0.3, 2, false), linear);
  const Superelement hard = test::Reduce(RodYaml(0.3, 2, false, 1e6, 1e5), linear);
  const std::string bodies =
      "name: contrast\nunits: SI\nbodies:\n"
      "  - {name: soft, superelement: soft.h5, nodes: {A: n0, B: n1}}\n"
      "  - {name: hard, superelement: hard.h5, placement: {position: [0.3, 0, 0]}, nodes: {A: n1, B: n2}}\n"
      "joints:\n  - {type: clamp, node: n0}\n";
  const Outcome st = Simulate("contrast_static",
                              bodies +
                                  "loads:\n  - {type: force, node: n2, force: [0, -0.01, 0]}\n"
                                  "analysis: {type: static, end_time: 1.0, steps: 1}\n",
                              {{"soft.h5", soft}, {"hard.h5", hard}}, "n2");
  ASSERT_TRUE(st.ok) << st.message;
  const double EI = 2e11 * M_PI * std::pow(0.006, 4) / 64, L1 = 0.3, L2 = 0.3, P = 0.01;
  const double w =
      P * (L1 * L1 * L1 + 3 * L1 * L1 * L2 + 3 * L1 * L2 * L2) / (3 * EI) + P * L2 * L2 * L2 / (3 * 1e6 * EI);
  const double got = -(st.tip.back().y());
  std::printf("[ info ] contrast 1e6 / 1e5: tip deflection %.6g m, beam theory %.6g m (%.2e)\n", got, w, got / w - 1);
  EXPECT_NEAR(got / w, 1.0, 1e-3);
  const Outcome dyn = Simulate("contrast_dynamic",
                               bodies +
                                   "loads:\n  - {type: gravity, g: [0, -9.81, 0]}\n"
                                   "analysis: {type: dynamic, end_time: 0.2, step: 1e-4, rho_inf: 0.8}\n",
                               {{"soft.h5", soft}, {"hard.h5", hard}}, "n2");
  ASSERT_TRUE(dyn.ok) << dyn.message;
  const double growth = LargestGrowth(dyn);
  const double weight_work = 1e5 * 0.00848 * 9.81 * 0.1;  // a generous scale: m_hard g times 10 cm
  EXPECT_LT(growth, 1e-3 * weight_work);
}

// A column past its Euler load: a clamped-free column of 4 bodies (1 m) under an axial tip load
// ramped to 1.5 P_cr with a lateral imperfection load of 1e-3 P_cr follows the buckled branch.
// Reference: the inextensible elastica, P / P_cr = (2 K(k) / pi)^2, lateral tip displacement
// 2 k / K(k) L (k = sin(alpha / 2), alpha the tip angle): 0.788 L at 1.5 P_cr; criterion 2% (4
// bodies with 2 modes each, the imperfection load). Without the imperfection the column stays
// straight, and the static analysis says that the tangent lost its positive definiteness.
TEST(NumericalStress, ColumnPastItsEulerLoad) {
  const Superelement seg = test::Reduce(RodYaml(0.25, 2, false));
  const double EI = 2e11 * M_PI * std::pow(0.006, 4) / 64, L = 1.0;
  const double P_cr = M_PI * M_PI * EI / (4 * L * L);
  // Elastica: K(k) by the arithmetic-geometric mean; k by bisection on (2K/pi)^2 = 1.5.
  auto K = [](double k) {
    double a = 1.0, b = std::sqrt(1 - k * k);
    for (int i = 0; i < 40; ++i) std::tie(a, b) = std::make_pair(0.5 * (a + b), std::sqrt(a * b));
    return M_PI / (2 * a);
  };
  double lo = 0.0, hi = 0.999;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (std::pow(2 * K(mid) / M_PI, 2) < 1.5 ? lo : hi) = mid;
  }
  const double elastica = 2 * lo / K(lo) * L;
  const std::string scene = ClampedChain("column", 4, 0.25) + "functions:\n  ramp: {type: linear}\n";
  char loads[400];
  std::snprintf(loads, sizeof loads,
                "loads:\n  - {type: force, node: n4, force: [%.17g, %.17g, 0], function: ramp}\n"
                "analysis: {type: static, end_time: 1.0, steps: 30}\n",
                -1.5 * P_cr, 1e-3 * P_cr);
  const Outcome imperfect = Simulate("column_imperfect", scene + loads, {{"seg.h5", seg}}, "n4");
  ASSERT_TRUE(imperfect.ok) << imperfect.message;
  const double lateral = std::abs(imperfect.tip.back().y());
  std::printf("[ info ] column at 1.5 P_cr with imperfection: lateral tip displacement %.4f L, elastica %.4f L\n",
              lateral / L, elastica / L);
  EXPECT_NEAR(lateral / elastica, 1.0, 0.02);
  std::snprintf(loads, sizeof loads,
                "loads:\n  - {type: force, node: n4, force: [%.17g, 0, 0], function: ramp}\n"
                "analysis: {type: static, end_time: 1.0, steps: 30}\n",
                -1.5 * P_cr);
  const Outcome perfect = Simulate("column_perfect", scene + loads, {{"seg.h5", seg}}, "n4");
  ASSERT_TRUE(perfect.ok) << perfect.message;
  std::string said;
  for (const std::string& w : perfect.warnings) said += w;
  std::printf("[ info ] perfect column: %s\n", said.c_str());
  EXPECT_NE(said.find("negative eigenvalues went from 0 to 2"), std::string::npos) << said;
  // The load where it is said: the step that crosses P_cr (pseudo-time 1/1.5 = 0.667).
  // Said at the first load step past the model's buckling load, which lies above the theory's
  // P_cr (pseudo-time 1/1.5 = 0.667): 4 linear bodies have no geometric stiffness inside (the
  // stiffening issue), measured 5-10% high.
  const size_t at = said.find("between pseudo-time ");
  ASSERT_NE(at, std::string::npos) << said;
  double from = 0, to = 0;
  ASSERT_EQ(std::sscanf(said.c_str() + at, "between pseudo-time %lf and %lf", &from, &to), 2) << said;
  EXPECT_GE(to, 1 / 1.5);
  EXPECT_LE(from, 1.15 / 1.5);
}

// Gravity in a static analysis (it was silently ignored): a clamped 1 m rod of 4 bodies sags
// under its own weight by q L^4 / 8 EI (Euler-Bernoulli; q = rho A g), criterion 0.5% (shear and
// the 2% sag's geometric nonlinearity are below 0.1%).
TEST(NumericalStress, StaticEquilibriumUnderGravity) {
  const Superelement seg = test::Reduce(RodYaml(0.25, 2, false));
  const std::string scene = ClampedChain("sag", 4, 0.25) +
                            "loads:\n  - {type: gravity, g: [0, -9.81, 0]}\n"
                            "analysis: {type: static, end_time: 1.0, steps: 2}\n";
  const Outcome r = Simulate("sag", scene, {{"seg.h5", seg}}, "n4");
  ASSERT_TRUE(r.ok) << r.message;
  const double EI = 2e11 * M_PI * std::pow(0.006, 4) / 64, q = 7870 * M_PI * 0.006 * 0.006 / 4 * 9.81;
  const double expected = q / (8 * EI);
  const double sag = -(r.origin + r.tip.back()).y();
  std::printf("[ info ] static sag under gravity %.6g m, q L^4 / 8 EI = %.6g m\n", sag, expected);
  EXPECT_NEAR(sag / expected, 1.0, 5e-3);
}

// A Cardan (universal) joint driven through a full turn at a bend of beta = 80 and 85 degrees,
// near its lock at 90 (the output turns up to 1/cos(beta) = 11.5x as fast as the input): a rigid
// input shaft on a revolute joint about x, its angle prescribed (static analysis, pseudo-time =
// angle), the universal joint (cross pins z in the input yoke, (-sin b, cos b, 0) in the output
// yoke) to a stiff output shaft superelement whose far end turns on a revolute joint about its
// axis d = (cos b, sin b, 0). Reference: the Cardan joint's closed form for these pins,
// tan(theta_out) = cos(beta) tan(theta_in). Criterion: 1e-6 rad over the turn (the loop closes
// without deformation).
TEST(NumericalStress, UniversalJointThroughNearGimbalLock) {
  const Superelement shaft = test::Reduce(RodYaml(0.3, 2, false));
  for (const double beta_deg : {80.0, 85.0}) {
    const double b = beta_deg * M_PI / 180;
    char scene[2048];
    std::snprintf(
        scene, sizeof scene,
        "name: cardan\nunits: SI\nbodies:\n"
        "  - {name: input, type: rigid, mass: 1, center_of_mass: [0, 0, 0], inertia: [1e-3, 1e-3, 1e-3],\n"
        "     points: {P: [0.1, 0, 0]}, placement: {position: [-0.1, 0, 0]}, nodes: {P: in}}\n"
        "  - {name: output, superelement: shaft.h5, placement: {rotation: [0, 0, %.17g]}, nodes: {A: u, B: o}}\n"
        "joints:\n"
        "  - {type: revolute, node: in, axis: [1, 0, 0], prescribed: turn}\n"
        "  - {type: universal, node: u, parent: in, axis: [0, 0, 1], axis2: [%.17g, %.17g, 0]}\n"
        "  - {type: revolute, node: o, axis: [%.17g, %.17g, 0]}\n"
        "functions:\n  turn: {type: linear}\n"
        "analysis: {type: static, end_time: %.17g, steps: 144}\n",
        b, -std::sin(b), std::cos(b), std::cos(b), std::sin(b), 2 * M_PI);
    const std::string dir = ::testing::TempDir() + "stress_cardan";
    std::filesystem::create_directories(dir);
    WriteSuperelementFile(shaft, dir + "/shaft.h5");
    const Scene sc = BuildScene(ParseScene(scene, dir + "/scene.yaml"));
    const int o = sc.node_index.at("o");
    SystemState state = InitialState(sc.model);
    StaticOptions options;
    options.end_time = 2 * M_PI;
    options.steps = 144;
    double worst = 0.0, previous = 0.0, unwrapped_reference = 0.0, fastest = 0.0;
    const StaticResult r =
        SolveStatic(sc.model, state, options, [&](const StaticStepReport& step, const SystemState& st) {
          const double theta_in = step.lambda;
          const double reference = std::atan2(std::cos(b) * std::sin(theta_in), std::cos(theta_in));
          double d = reference - previous;  // unwrap the closed form along the turn
          d -= 2 * M_PI * std::round(d / (2 * M_PI));
          fastest = std::max(fastest, std::abs(d) / (2 * M_PI / 144));
          unwrapped_reference += d;
          previous = reference;
          worst = std::max(worst, std::abs(st.z[o][0] - unwrapped_reference));
        });
    ASSERT_TRUE(r.ok) << beta_deg << " deg: " << r.message;
    std::printf(
        "[ info ] Cardan joint at %.0f deg: output angle within %.2e rad of the closed form over a turn "
        "(output up to %.1fx the input rate per step)\n",
        beta_deg, worst, fastest);
    EXPECT_LT(worst, 1e-6) << beta_deg;
  }
}

// Newton's tolerance below round-off: a clear message, no hang, no silent slowdown.
TEST(NumericalStress, ToleranceBelowRoundOffIsSaid) {
  const Superelement rod = test::Reduce(RodYaml(0.3, 2, false));
  const Outcome r = Simulate(
      "roundoff",
      Pendulum(false, Eigen::Vector3d::Zero(), "{type: dynamic, end_time: 0.05, step: 1e-3, tolerance: 1e-20}"),
      {{"rod.h5", rod}}, "tip");
  ASSERT_TRUE(r.ok) << r.message;
  bool said = false;
  for (const std::string& w : r.warnings) said |= w.find("round-off") != std::string::npos;
  EXPECT_TRUE(said);
}

}  // namespace
}  // namespace femb
