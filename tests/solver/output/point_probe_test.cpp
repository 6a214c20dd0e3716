// Point probes (a body and a point: position, velocity, acceleration, deformation of the
// material point there, interpolated from the file's mesh and mode shapes) and effort probes (the
// generalized force that keeps a prescribed joint coordinate on its time function), through the
// scene reader, BuildScene and ResultsRecorder as femb-solve runs them, against independent
// references: the unreduced finite element model's static solution, the interface node where the
// point coincides with it, the time derivative of the recorded positions, the centripetal
// acceleration of a turning body, and the rigid pendulum's and four-bar's equations of motion.
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/SparseCholesky>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "formats/hdf5_file.h"
#include "formats/input_error.h"
#include "formats/part_file.h"
#include "formats/scene_file.h"
#include "formats/superelement_file.h"
#include "reducer/fe/solid_model.h"
#include "solver/analysis/dynamic_analysis.h"
#include "solver/analysis/static_analysis.h"
#include "solver/joints/joint_tree.h"
#include "solver/output/results_recorder.h"
#include "solver/scene/scene_builder.h"
#include "test_util.h"

namespace femb {
namespace {

namespace fs = std::filesystem;

// A steel bar 1 m x 50 mm x 50 mm in TET10 (mesh size 25 mm), RBE2 interfaces on its end faces,
// 6 internal modes, linear inside (no geometric stiffening: the full model below is linear).
const char* kBarPart = R"(name: bar
type: solid
units: SI
material: {E: 2.1e11, nu: 0.3, rho: 7850}
geometry: {shape: box, size: [1.0, 0.05, 0.05]}
mesh: {size: 0.025, order: 2}
interfaces:
  - {name: root, group: xmin, coupling: rbe2}
  - {name: tip, group: xmax, coupling: rbe2}
reduction: {internal_modes: 6, floating_frame: center_of_mass, geometric_stiffening: false}
)";

std::string Folder(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("femb_point_probe_" + std::to_string(::getpid()) + "_" + name);
  fs::create_directories(dir);
  return dir.string();
}

// The probes of a run by column name, in full precision (results.h5 /probes; probes.csv has
// 10 significant digits), with the time and the kinetic energy.
std::map<std::string, std::vector<double>> ReadProbes(const std::string& path) {
  h5::Reader r(path);
  std::map<std::string, std::vector<double>> columns;
  const Eigen::VectorXd t = r.Vector("/time");
  columns["time"].assign(t.data(), t.data() + t.size());
  const Eigen::VectorXd kinetic = r.Vector("/energy/kinetic");
  columns["kinetic_energy"].assign(kinetic.data(), kinetic.data() + kinetic.size());
  const std::vector<std::string> names = r.Strings("/probes/names");
  const Eigen::MatrixXd values = r.Matrix("/probes/values");
  for (size_t i = 0; i < names.size(); ++i) {
    for (long k = 0; k < values.rows(); ++k) columns[names[i]].push_back(values(k, long(i)));
  }
  return columns;
}

// Runs a scene as femb-solve does (static: the load steps; dynamic: every step recorded, the
// reactions from each output state's consistent accelerations when the scene asks for them)
// and returns its probes.
std::map<std::string, std::vector<double>> RunScene(const std::string& dir, const std::string& scene_yaml) {
  const std::string path = dir + "/scene.yaml";
  std::ofstream(path) << scene_yaml;
  const Scene scene = BuildScene(ReadSceneFile(path));
  ResultsRecorder recorder(scene, dir + "/out");
  const SceneSpec& spec = scene.spec;
  if (spec.analysis.type == AnalysisType::kStatic) {
    SystemState state = InitialState(scene.model);
    recorder.Record(0.0, state, Eigen::VectorXd(), 0.0, 0.0, 0.0);
    StaticOptions options;
    options.steps = spec.analysis.steps;
    options.end_time = spec.analysis.end_time;
    options.tolerance = spec.analysis.tolerance;
    const StaticResult r =
        SolveStatic(scene.model, state, options, [&](const StaticStepReport& s, const SystemState& st) {
          recorder.Record(s.lambda, st, Eigen::VectorXd(), 0.0, s.elastic_energy, s.external_work);
        });
    EXPECT_TRUE(r.ok) << r.message;
    recorder.Finish(r.ok ? "completed" : r.message);
  } else {
    DynamicState state = InitialDynamicState(scene.model, InitialState(scene.model), scene.initial_velocity);
    const auto record = [&](double t, const DynamicState& st, double kinetic) {
      const DynamicState out = spec.reactions ? WithConsistentAccelerations(scene.model, st) : st;
      const auto reactions =
          spec.reactions ? DynamicReactions(scene.model, out) : std::vector<Eigen::Matrix<double, 6, 1>>();
      recorder.Record(t, out.config, out.W, kinetic, 0.0, 0.0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                      spec.reactions ? &reactions : nullptr, &out.Wdot);
    };
    record(0.0, state, Measure(scene.model, state).kinetic_energy);
    DynamicOptions options;
    options.step = spec.analysis.step;
    options.end_time = spec.analysis.end_time;
    options.rho_inf = spec.analysis.rho_inf;
    options.tolerance = spec.analysis.tolerance;
    const DynamicResult r =
        SolveDynamic(scene.model, state, options,
                     [&](const DynamicStepReport& s, const DynamicState& st) { record(s.t, st, s.kinetic_energy); });
    EXPECT_TRUE(r.ok) << r.message;
    recorder.Finish(r.ok ? "completed" : r.message);
  }
  return ReadProbes(recorder.h5_path());
}

class PointProbeTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(Folder("bar"));
    WriteSuperelementFile(test::Reduce(kBarPart), *dir_ + "/bar.h5");
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
  }
  static std::string* dir_;
};
std::string* PointProbeTest::dir_ = nullptr;

// Static: the bar clamped at its root, a transverse force at its tip. The Craig-Bampton basis
// holds the static response to interface loads exactly, so a point's deflection equals the
// unreduced model's (the same mesh and couplings, solved here with a sparse Cholesky factor) to
// 1e-6 of it. The floating frame's geometric nonlinearity is taken out by loading with +F and
// then -F (1 N, a tip slope of 5e-6): half the difference of the two positions is the linear
// deflection to O(slope^2). The tip face's centre point (on the
// RBE2 face, which moves rigidly with the interface node at its centroid) moves as the node, to
// 1e-9 of its displacement.
TEST_F(PointProbeTest, StaticDeflectionEqualsTheUnreducedModel) {
  const Eigen::Vector3d inside(0.4637, 0.0191, 0.0313), face_centre(1.0, 0.025, 0.025);
  const std::string scene = test::Replace(R"(name: bar_static
units: SI
bodies:
  - {name: bar, superelement: BAR, nodes: {root: A, tip: B}, placement: {position: [-0.4637, -0.0191, -0.0313]}}
joints:
  - {type: clamp, node: A}
functions:
  both: {type: table, points: [[0, 0], [1, 1], [2, -1]]}
loads:
  - {type: force, node: B, force: [0, -0.6, 0.8], function: both}
analysis: {type: static, end_time: 2, steps: 2, tolerance: 1.0e-13}
outputs:
  animation: false
  probes:
    - {name: tip, node: B, quantities: [position]}
    - {name: face, body: bar, point: [0.5363, 0.0059, -0.0063], quantities: [position]}
    - {name: p, body: bar, point: [0, 0, 0], quantities: [position, deformation]}
)",
                                          "BAR", *dir_ + "/bar.h5");
  const auto probes = RunScene(Folder("static"), scene);

  // The unreduced model: its K over the model DOFs (RBE2 couplings folded in), the root's six
  // interface DOFs held, the force on the tip's.
  const FeModel full = BuildSolidModel(ParsePart(kBarPart, "bar.yaml"));
  std::vector<int> held;
  for (const FullDof& d : full.interface_dofs[0]) held.push_back(d.value);
  std::vector<int> index(size_t(full.n_dofs()), -1);
  int n_free = 0;
  for (int i = 0; i < full.n_dofs(); ++i)
    if (std::find(held.begin(), held.end(), i) == held.end()) index[size_t(i)] = n_free++;
  std::vector<Eigen::Triplet<double>> entries;
  for (int c = 0; c < full.K.outerSize(); ++c)
    for (SparseMatrix::InnerIterator it(full.K, c); it; ++it)
      if (index[size_t(it.row())] >= 0 && index[size_t(c)] >= 0)
        entries.emplace_back(index[size_t(it.row())], index[size_t(c)], it.value());
  SparseMatrix K(n_free, n_free);
  K.setFromTriplets(entries.begin(), entries.end());
  Eigen::VectorXd f = Eigen::VectorXd::Zero(n_free);
  f[index[size_t(full.interface_dofs[1][1].value)]] = -0.6;
  f[index[size_t(full.interface_dofs[1][2].value)]] = 0.8;
  Eigen::SimplicialLDLT<SparseMatrix> solver(K);
  ASSERT_EQ(solver.info(), Eigen::Success);
  const Eigen::VectorXd u_free = solver.solve(f);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(full.n_dofs());
  for (int i = 0; i < full.n_dofs(); ++i)
    if (index[size_t(i)] >= 0) u[i] = u_free[index[size_t(i)]];
  const std::optional<SparseMatrix> at = full.interpolate_at(inside);
  ASSERT_TRUE(at.has_value());
  const Eigen::Vector3d reference = (*at * u).head<3>();

  const auto odd = [&](const std::string& name) { return 0.5 * (probes.at(name)[1] - probes.at(name)[2]); };
  const Eigen::Vector3d moved(odd("p.position.x"), odd("p.position.y"), odd("p.position.z"));
  std::printf("point (0.4637, 0.0191, 0.0313): deflection %.9e %.9e %.9e, unreduced model %.9e %.9e %.9e\n", moved.x(),
              moved.y(), moved.z(), reference.x(), reference.y(), reference.z());
  EXPECT_LT((moved - reference).norm(), 1e-6 * reference.norm());
  // The deformation is the elastic part relative to the floating frame: not the displacement
  // of a clamped bar, but with it the same size (the frame moves little).
  const Eigen::Vector3d deformation(odd("p.deformation.x"), odd("p.deformation.y"), odd("p.deformation.z"));
  EXPECT_GT(deformation.norm(), 1e-3 * reference.norm());
  (void)face_centre;
  const auto at_step = [&](const std::string& name, int i) {
    return Eigen::Vector3d(probes.at(name + ".x")[size_t(i)], probes.at(name + ".y")[size_t(i)],
                           probes.at(name + ".z")[size_t(i)]);
  };
  for (int i : {1, 2}) {
    const Eigen::Vector3d moved_node = at_step("tip.position", i) - at_step("tip.position", 0);
    EXPECT_LT((at_step("face.position", i) - at_step("tip.position", i)).norm(), 1e-9 * moved_node.norm());
  }
}

// A beam's points between its nodes: a cantilever of 4 Euler-Bernoulli elements ('general'
// section, rigid in shear) under a static tip force F in y. Beam theory's deflection
// w(x) = F x^2 (3L - x) / (6 E I) is a cubic, which the elements hold exactly at the nodes and
// Hermite's cubic between them: a point at x = 0.37 L on the axis deflects by w(0.37 L), and one
// 10 mm off the axis in y moves along x by -0.01 w'(x) (the section turns with the slope), each
// within 1e-6 of the tip deflection (the nearest node, at 0.25 L, deflects 52% less). The
// floating frame's nonlinearity is taken out with +F and -F, as above.
TEST(BeamPointProbe, PointsBetweenNodesFollowBeamTheory) {
  const std::string dir = Folder("beam");
  const std::string part = test::StraightBeamYaml(
      1.0, 4, "{shape: general, A: 1.0e-4, Iy: 1.0e-8, Iz: 1.0e-8, J: 2.0e-8}", "{E: 2.1e11, nu: 0.3, rho: 7850}",
      "[{name: A}, {name: B}]", "reduction: {internal_modes: 4, keep_mesh: true}\n");
  WriteSuperelementFile(test::Reduce(part), dir + "/beam.h5");
  const std::string scene = test::Replace(R"(name: beam_static
units: SI
bodies:
  - {name: beam, superelement: BEAM, nodes: {A: a, B: b}}
joints:
  - {type: clamp, node: a}
functions:
  both: {type: table, points: [[0, 0], [1, 1], [2, -1]]}
loads:
  - {type: force, node: b, force: [0, 1, 0], function: both}
analysis: {type: static, end_time: 2, steps: 2, tolerance: 1.0e-13}
outputs:
  animation: false
  probes:
    - {name: tip, node: b, quantities: [position]}
    - {name: axis, body: beam, point: [0.37, 0, 0], quantities: [position]}
    - {name: off, body: beam, point: [0.37, 0.01, 0], quantities: [position]}
)",
                                          "BEAM", dir + "/beam.h5");
  const auto probes = RunScene(dir, scene);
  const auto odd = [&](const std::string& name) { return 0.5 * (probes.at(name)[1] - probes.at(name)[2]); };
  const double EI = 2.1e11 * 1e-8, x = 0.37;
  const double w = x * x * (3 - x) / (6 * EI), slope = x * (2 - x) / (2 * EI), tip = 1.0 / (3 * EI);
  std::printf(
      "x = 0.37 L: deflection %.9e (beam theory %.9e), off-axis point's axial motion %.9e (%.9e); tip %.9e (%.9e)\n",
      odd("axis.position.y"), w, odd("off.position.x"), -0.01 * slope, odd("tip.position.y"), tip);
  EXPECT_LT(std::abs(odd("tip.position.y") - tip), 1e-6 * tip);
  EXPECT_LT(std::abs(odd("axis.position.y") - w), 1e-6 * tip);
  EXPECT_LT(std::abs(odd("axis.position.x")), 1e-6 * tip);
  EXPECT_LT(std::abs(odd("off.position.y") - w), 1e-6 * tip);
  EXPECT_LT(std::abs(odd("off.position.x") + 0.01 * slope), 1e-6 * tip);
  fs::remove_all(dir);
}

// Dynamic: the same bar, clamped, a force ramped on at its tip in 0.5 ms (3 ms,
// generalized-alpha with rho_inf 0.9). The recorded point velocity is the time derivative of the
// recorded position, and the acceleration that of the velocity, to the step's accuracy: the
// largest difference between them and the central differences of the output series is below
// 1e-3 of the peak at 10 us for the velocity and falls as h^2 (at least 3x at half the step);
// for the acceleration it falls as h (at least 1.8x): generalized-alpha's velocity update uses its
// algorithmic acceleration, which runs (alpha_m - alpha_f) h = 0.05 h off the true one (the
// recorded accelerations). The values from results.h5 /probes (probes.csv's 10 digits put a noise
// of 1e-5 m/s on the differences of positions 0.7 m from the origin).
TEST_F(PointProbeTest, VelocityAndAccelerationAreRatesOfThePosition) {
  const std::string scene = test::Replace(R"(name: bar_dynamic
units: SI
bodies:
  - {name: bar, superelement: BAR, nodes: {root: A, tip: B}, placement: {position: [-0.7, -0.04, -0.01]}}
joints:
  - {type: clamp, node: A}
functions:
  on: {type: ramp, value: 1, t_start: 0, t_end: 0.0005}
loads:
  - {type: force, node: B, force: [0, -1000, 300], function: on}
analysis: {type: dynamic, end_time: 0.003, step: STEP, rho_inf: 0.9, tolerance: 1.0e-11}
outputs:
  animation: false
  probes:
    - {name: p, body: bar, point: [0, 0, 0], quantities: [position, velocity, acceleration]}
)",
                                          "BAR", *dir_ + "/bar.h5");
  std::map<std::string, double> errors[2];
  for (int run = 0; run < 2; ++run) {
    const auto probes = RunScene(Folder("dynamic"), test::Replace(scene, "STEP", run == 0 ? "1.0e-5" : "5.0e-6"));
    const std::vector<double>& t = probes.at("time");
    for (const char* c : {"x", "y", "z"}) {
      const std::vector<double>& x = probes.at(std::string("p.position.") + c);
      const std::vector<double>& v = probes.at(std::string("p.velocity.") + c);
      const std::vector<double>& a = probes.at(std::string("p.acceleration.") + c);
      double v_peak = 0, a_peak = 0, v_error = 0, a_error = 0;
      for (size_t i = 1; i + 1 < t.size(); ++i) {
        const double dt = t[i + 1] - t[i - 1];
        v_peak = std::max(v_peak, std::abs(v[i]));
        a_peak = std::max(a_peak, std::abs(a[i]));
        v_error = std::max(v_error, std::abs((x[i + 1] - x[i - 1]) / dt - v[i]));
        a_error = std::max(a_error, std::abs((v[i + 1] - v[i - 1]) / dt - a[i]));
      }
      std::printf(
          "h = %s, %s: velocity peak %.4g, largest difference from d/dt position %.3g; acceleration peak %.4g, "
          "from d/dt velocity %.3g\n",
          run == 0 ? "10 us" : "5 us", c, v_peak, v_error, a_peak, a_error);
      EXPECT_GT(v_peak, 0.0);
      errors[run][std::string("v") + c] = v_error / v_peak;
      errors[run][std::string("a") + c] = a_error / a_peak;
    }
  }
  for (const auto& [name, e] : errors[0]) {
    if (name[0] == 'v') {
      EXPECT_LT(e, 1e-3) << name;
    }
    EXPECT_GT(e, (name[0] == 'v' ? 3.0 : 1.8) * errors[1][name]) << name;
  }
}

// A turning body: the bar on a revolute joint at its root about its own axis (x, through the end
// faces' centroids), spun up smoothly to 100 rad/s in 0.5 s and then turning steadily. (About a
// transverse axis the spin-up bends the bar and leaves an undamped ringing of the tip, whose
// acceleration is 5e-3 of the centripetal one: the interface motion is no internal mode that
// modal damping would damp.) A point at radius r from the axis then accelerates towards it with
// omega^2 r and moves with omega r along the circle: within 1e-6 of both over the last 0.1 s (r
// from the recorded position; measured 7e-8 and 7e-10).
TEST_F(PointProbeTest, TurningBodyAcceleratesCentripetally) {
  const std::string scene = test::Replace(R"(name: bar_turning
units: SI
bodies:
  - {name: bar, superelement: BAR, nodes: {root: A, tip: B}}
joints:
  - {type: revolute, node: A, axis: [1, 0, 0], prescribed: spin}
functions:
  spin: {type: spin_up, omega: 100, t_spin: 0.5}
analysis: {type: dynamic, end_time: 0.6, step: 1.0e-4, rho_inf: 0.5, tolerance: 1.0e-11}
outputs:
  animation: false
  probes:
    - {name: p, body: bar, point: [0.6, 0.045, 0.04], quantities: [position, velocity, acceleration]}
)",
                                          "BAR", *dir_ + "/bar.h5");
  const auto probes = RunScene(Folder("turning"), scene);
  const std::vector<double>& t = probes.at("time");
  double worst_a = 0, worst_v = 0;
  int checked = 0;
  for (size_t i = 0; i < t.size(); ++i) {
    if (t[i] < 0.5 - 1e-12) continue;
    // The axis: x through the root face's centroid (0, 0.025, 0.025).
    const Eigen::Vector3d r(0.0, probes.at("p.position.y")[i] - 0.025, probes.at("p.position.z")[i] - 0.025);
    const Eigen::Vector3d a(probes.at("p.acceleration.x")[i], probes.at("p.acceleration.y")[i],
                            probes.at("p.acceleration.z")[i]);
    const Eigen::Vector3d v(probes.at("p.velocity.x")[i], probes.at("p.velocity.y")[i], probes.at("p.velocity.z")[i]);
    const Eigen::Vector3d a_ref = -1e4 * r, v_ref = 100.0 * Eigen::Vector3d::UnitX().cross(r);
    worst_a = std::max(worst_a, (a - a_ref).norm() / a_ref.norm());
    worst_v = std::max(worst_v, (v - v_ref).norm() / v_ref.norm());
    ++checked;
  }
  std::printf(
      "turning at 100 rad/s: point acceleration within %.2e of omega^2 r, velocity within %.2e of omega r (%d "
      "outputs)\n",
      worst_a, worst_v, checked);
  EXPECT_GT(checked, 900);
  EXPECT_LT(worst_a, 1e-6);
  EXPECT_LT(worst_v, 1e-6);
}

// Effort of a driven rigid pendulum (mass 2 kg, centre of mass 0.3 m from the pin, 0.01 kg m^2
// about it, gravity -y): the torque that keeps theta(t) is I_P alpha + m g l cos(theta) about the
// pin axis (I_P = I_c + m l^2; theta from the horizontal), to 1e-8 of its peak, at constant speed
// and under a sine drive. The pendulum's centre of mass, a point probe on the rigid body, moves on
// the circle of radius l.
TEST(EffortProbe, DrivenPendulumNeedsTheTorqueOfItsEquationOfMotion) {
  const double m = 2.0, l = 0.3, I_P = 0.01 + m * l * l, g = 9.81;
  for (const std::string drive : {"{type: linear, slope: 3}", "{type: sine, amplitude: 0.5, frequency: 1}"}) {
    const std::string scene = test::Replace(R"(name: pendulum
units: SI
bodies:
  - {name: arm, type: rigid, mass: 2, inertia: [0.001, 0.01, 0.01], center_of_mass: [0.3, 0, 0],
     points: {P: [0, 0, 0]}, nodes: {P: pin}}
joints:
  - {type: revolute, node: pin, axis: [0, 0, 1], prescribed: drive}
functions:
  drive: DRIVE
loads:
  - {type: gravity, g: [0, -9.81, 0]}
analysis: {type: dynamic, end_time: 1, step: 1.0e-3, tolerance: 1.0e-12}
outputs:
  animation: false
  probes:
    - {name: pin, node: pin, quantities: [joint, effort]}
    - {name: com, body: arm, point: [0.3, 0, 0], quantities: [position]}
)",
                                            "DRIVE", drive);
    const auto probes = RunScene(Folder("pendulum"), scene);
    const bool linear = drive.find("linear") != std::string::npos;
    double peak = 0, error = 0, radius_error = 0;
    for (size_t i = 0; i < probes.at("time").size(); ++i) {
      const double t = probes.at("time")[i];
      const double theta = linear ? 3 * t : 0.5 * std::sin(2 * M_PI * t);
      const double alpha = linear ? 0.0 : -0.5 * 4 * M_PI * M_PI * std::sin(2 * M_PI * t);
      const double torque = I_P * alpha + m * g * l * std::cos(theta);
      EXPECT_NEAR(probes.at("pin.joint.0")[i], theta, 1e-9);
      peak = std::max(peak, std::abs(torque));
      error = std::max(error, std::abs(probes.at("pin.effort.0")[i] - torque));
      radius_error = std::max(radius_error,
                              std::abs(std::hypot(probes.at("com.position.x")[i], probes.at("com.position.y")[i]) - l));
    }
    std::printf("pendulum, drive %s: effort within %.2e of I alpha + m g l cos(theta) (peak %.4g N m)\n", drive.c_str(),
                error, peak);
    EXPECT_LT(error, 1e-8 * peak);
    EXPECT_LT(radius_error, 1e-9);
  }
}

// The crank torque of a rigid four-bar in a vertical plane (crank 0.1 m driven at 10 rad/s,
// coupler 0.403 m, rocker 0.304 m, ground 0.4 m; the loop closed by a cut revolute), against the
// power balance tau omega = d/dt (kinetic energy + potential energy of gravity), from results.h5's
// kinetic energy and the links' centres of mass (point probes, /probes), by central differences
// at 50 us: within 1e-6 of the torque's peak (measured 5e-7).
TEST(EffortProbe, FourBarCrankTorqueBalancesThePower) {
  const std::string scene = R"(name: four_bar
units: SI
bodies:
  - {name: crank, type: rigid, mass: 0.4, inertia: [1.0e-5, 4.0e-4, 4.0e-4], center_of_mass: [0, 0.05, 0],
     points: {A: [0, 0, 0], B: [0, 0.1, 0]}, nodes: {A: A, B: B1}}
  - {name: coupler, type: rigid, mass: 1.2, inertia: [1.0e-4, 1.6e-2, 1.6e-2], center_of_mass: [0.175, 0.2, 0],
     points: {B: [0, 0.1, 0], C: [0.35, 0.3, 0]}, nodes: {B: B2, C: C2}}
  - {name: rocker, type: rigid, mass: 0.9, inertia: [1.0e-4, 7.0e-3, 7.0e-3], center_of_mass: [0.375, 0.15, 0],
     points: {D: [0.4, 0, 0], C: [0.35, 0.3, 0]}, nodes: {D: D, C: C3}}
joints:
  - {type: revolute, node: A, axis: [0, 0, 1], prescribed: crank}
  - {type: revolute, node: B2, parent: B1, axis: [0, 0, 1]}
  - {type: revolute, node: C3, parent: C2, axis: [0, 0, 1]}
  - {type: revolute, node: D, axis: [0, 0, 1]}
functions:
  crank: {type: linear, slope: 10}
loads:
  - {type: gravity, g: [0, -9.81, 0]}
analysis: {type: dynamic, end_time: 0.7, step: 5.0e-5, rho_inf: 0.9, tolerance: 1.0e-12}
outputs:
  animation: false
  probes:
    - {name: crank, node: A, quantities: [effort]}
    - {name: g1, body: crank, point: [0, 0.05, 0], quantities: [position]}
    - {name: g2, body: coupler, point: [0.175, 0.2, 0], quantities: [position]}
    - {name: g3, body: rocker, point: [0.375, 0.15, 0], quantities: [position]}
)";
  const auto probes = RunScene(Folder("four_bar"), scene);
  const std::vector<double>& t = probes.at("time");
  const auto energy = [&](size_t i) {
    return probes.at("kinetic_energy")[i] +
           9.81 * (0.4 * probes.at("g1.position.y")[i] + 1.2 * probes.at("g2.position.y")[i] +
                   0.9 * probes.at("g3.position.y")[i]);
  };
  double peak = 0, error = 0;
  for (size_t i = 1; i + 1 < t.size(); ++i) {
    const double power = (energy(i + 1) - energy(i - 1)) / (t[i + 1] - t[i - 1]);
    peak = std::max(peak, std::abs(probes.at("crank.effort.0")[i]));
    error = std::max(error, std::abs(probes.at("crank.effort.0")[i] - power / 10.0));
  }
  std::printf("four-bar: crank torque peak %.4g N m, within %.2e of the power balance / omega\n", peak, error);
  EXPECT_GT(peak, 1.0);
  EXPECT_LT(error, 1e-6 * peak);
}

// One line and no output for a point outside the body by more than the mesh size, an effort
// probe on a node without a prescribed joint, and a stress_exclude naming an unknown interface.
TEST_F(PointProbeTest, BadProbesAreRefusedWithOneLine) {
  const std::string base = test::Replace(R"(name: bar_bad
units: SI
bodies:
  - {name: bar, superelement: BAR, nodes: {root: A, tip: B}}
joints:
  - {type: clamp, node: A}
analysis: {type: static, end_time: 1, steps: 1}
outputs:
  stresses: true
  probes:
    - PROBE
)",
                                         "BAR", *dir_ + "/bar.h5");
  const std::string dir = Folder("bad");
  const auto message = [&](const std::string& probe, const std::string& extra = "") {
    std::ofstream(dir + "/scene.yaml") << test::Replace(base, "PROBE", probe) + extra;
    return test::ThrownMessage([&] { BuildScene(ReadSceneFile(dir + "/scene.yaml")); });
  };
  const std::string outside = message("{name: p, body: bar, point: [0.5, 0.2, 0.025], quantities: [position]}");
  EXPECT_NE(outside.find("probe 'p': point (0.5, 0.2, 0.025) lies outside body 'bar'"), std::string::npos) << outside;
  EXPECT_NE(outside.find("scene.yaml:"), std::string::npos) << outside;
  const std::string effort = message("{name: e, node: B, quantities: [effort]}");
  EXPECT_NE(effort.find("probe 'e': node 'B' has no prescribed joint coordinate"), std::string::npos) << effort;
  const std::string exclude = message("{name: t, node: B, quantities: [position]}",
                                      "  stress_exclude: {distance: 0.01, interfaces: [bar.middle]}\n");
  EXPECT_NE(exclude.find("stress_exclude.interfaces: body 'bar' has no interface 'middle' (it has: root, tip)"),
            std::string::npos)
      << exclude;
  // Just outside a face (less than the mesh size): the nearest mesh node, said in the log.
  std::ofstream(dir + "/scene.yaml") << test::Replace(
      base, "PROBE", "{name: p, body: bar, point: [0.5, 0.0501, 0.025], quantities: [position]}");
  const Scene scene = BuildScene(ReadSceneFile(dir + "/scene.yaml"));
  bool said = false;
  for (const std::string& note : scene.notes)
    said |= note.find("probe 'p': body 'bar' at its mesh node") != std::string::npos;
  EXPECT_TRUE(said);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace femb
