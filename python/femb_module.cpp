// femb._core: the C++ library as the Python package femb sees it (python/femb/__init__.py builds
// the user's API on it). The three jobs as the programs do them: ReduceToFile (femb-reduce),
// the superelement file read and checked (femb-inspect), SolveRun (femb-solve). Input errors
// raise femb.InputError with the program's one line; numerical failures femb.NumericalError.
// Matrices come back as numpy arrays that own the Eigen data moved into them (no copy).
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <csignal>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

#include "formats/input_error.h"
#include "formats/part_file.h"
#include "formats/scene_file.h"
#include "formats/superelement.h"
#include "formats/superelement_file.h"
#include "inspect/report.h"
#include "inspect/superelement_checks.h"
#include "inspect/vtu_writer.h"
#include "reducer/reduce_file.h"
#include "solver/joints/joint_tree.h"
#include "solver/run/solve_run.h"

namespace py = pybind11;

namespace {

// A femb error raised in Python: the class, and the message (the program's line).
struct PythonError {
  PyObject* type;
  std::string message;
};

PyObject* g_numerical_error = nullptr;
PyObject* g_refused_error = nullptr;

[[noreturn]] void Raise(PyObject* type, const std::string& message) {
  PyErr_SetString(type, message.c_str());
  throw py::error_already_set();
}

// A Python callable as the library's line sink: called with the GIL held (the run releases it);
// an exception it raises is kept and raised again when the run returns.
std::function<void(const std::string&)> LineSink(const py::object& callback) {
  if (callback.is_none()) return nullptr;
  return [callback](const std::string& line) {
    py::gil_scoped_acquire gil;
    try {
      callback(line);
    } catch (py::error_already_set& e) {
      e.discard_as_unraisable("femb progress callback");
    }
  };
}

// femb.reduce: the part (its text and the name its lines are reported under, a path whose
// folder relative paths start from) reduced and written to `output`.
femb::Superelement Reduce(const std::string& text, const std::string& name, const std::vector<std::string>& overrides,
                          const std::string& output, const py::object& progress, const py::object& warning) {
  const femb::PartSpec part = femb::ParsePart(text, name, overrides);
  const auto say = LineSink(progress), warn = LineSink(warning);
  femb::ProgressFn stages;
  if (say) {
    stages = [say](const std::string& stage, double seconds, const std::string& detail) {
      char buffer[96];
      std::snprintf(buffer, sizeof buffer, "%-16s %8.3f s  ", stage.c_str(), seconds);
      say(buffer + detail);
    };
  }
  femb::ReduceFileOutcome outcome;
  {
    py::gil_scoped_release release;
    outcome = femb::ReduceToFile(part, output.empty() ? part.name + ".h5" : output, stages, warn);
  }
  if (outcome.exit_code == 4) Raise(g_refused_error, outcome.error);
  if (outcome.exit_code != 0) Raise(g_numerical_error, outcome.error);
  return std::move(outcome.superelement);
}

// A Python function behind a force: its reference released with the GIL held, wherever the last
// copy of the force goes; called with the GIL (the run releases it); what it returns checked.
// Whatever goes wrong (an exception, a wrong shape, a value not finite) is a UserForceError
// naming the force and the time.
class PythonFunction {
 public:
  PythonFunction(const std::string& name, const py::object& function)
      : name_(name), function_(new py::object(function), [](py::object* o) {
          py::gil_scoped_acquire gil;
          delete o;
        }) {}

  template <typename... Args>
  py::object Call(double t, const Args&... args) const {
    try {
      return (*function_)(t, args...);
    } catch (py::error_already_set& e) {
      throw femb::UserForceError(Where(t) + "raised " + e.what());
    }
  }
  // `value` as rows x cols numbers (row-major) into `out`.
  void Take(double t, const py::handle& value, long rows, long cols, const char* what, double* out) const {
    using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;
    Array a;
    try {
      a = Array::ensure(value);
    } catch (py::error_already_set&) {
    }
    if (!a || a.size() != rows * cols || (cols > 1 && (a.ndim() != 2 || a.shape(0) != rows))) {
      throw femb::UserForceError(Where(t) + what + " must be " + std::to_string(rows) +
                                 (cols > 1 ? " x " + std::to_string(cols) : std::string(" numbers")) + ", got " +
                                 std::string(py::str(value.attr("__repr__")())).substr(0, 80));
    }
    for (long i = 0; i < rows * cols; ++i) {
      out[i] = a.data()[i];
      if (!std::isfinite(out[i])) throw femb::UserForceError(Where(t) + what + " is not finite");
    }
  }
  // What the function returns: without a Jacobian the value (n numbers) into `value`, false;
  // with one, the triple (value, K, C), K and C n x cols into *K and *C where asked, true. `names`
  // says what each is ("the force ...", "K = ...", "C = ..."), `triple` how the triple reads.
  template <typename Matrix>
  bool TakeValue(double t, const py::object& result, bool jacobian, long n, long cols,
                 const std::array<const char*, 3>& names, const char* triple, double* value, Matrix* K,
                 Matrix* C) const {
    if (!jacobian) {
      Take(t, result, n, 1, names[0], value);
      return false;
    }
    if (!py::isinstance<py::tuple>(result) || py::len(result) != 3) {
      throw femb::UserForceError(Where(t) + "with jacobian=True, return " + triple);
    }
    const py::tuple parts = result.cast<py::tuple>();
    Take(t, parts[0], n, 1, names[0], value);
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> m(n, cols);
    Matrix* out[2] = {K, C};
    for (int i = 0; i < 2; ++i) {
      if (!out[i]) continue;
      Take(t, parts[i + 1], n, cols, names[size_t(i) + 1], m.data());
      *out[i] = m;
    }
    return true;
  }
  std::string Where(double t) const {
    char where[160];
    std::snprintf(where, sizeof where, "force '%s' at t = %.9g: ", name_.c_str(), t);
    return where;
  }

 private:
  std::string name_;
  std::shared_ptr<py::object> function_;
};

constexpr const char* kForceWhat = "the force (fx, fy, fz, mx, my, mz)";

// A Python function as a UserNodeForce: function(t, position, rotation, velocity,
// angular_velocity) -> f (6: force, moment about the node, world axes), or with `jacobian` ->
// (f, K, C), K = df/d(x, theta), C = df/d(v, omega) (6 x 6).
femb::UserNodeForce PythonForce(const std::string& name, const py::object& function, bool jacobian) {
  const PythonFunction fn(name, function);
  femb::UserNodeForce force;
  force.name = name;
  force.evaluate = [fn, jacobian](double t, const Eigen::Vector3d& x, const Eigen::Matrix3d& R,
                                  const Eigen::Vector3d& v, const Eigen::Vector3d& w, femb::UserNodeForce::Vector6& f,
                                  femb::UserNodeForce::Matrix6* K, femb::UserNodeForce::Matrix6* C) {
    py::gil_scoped_acquire gil;
    return fn.TakeValue(t, fn.Call(t, x, R, v, w), jacobian, 6, 6,
                        {kForceWhat, "K = df/d(x, theta)", "C = df/d(v, omega)"}, "(f, K, C)", f.data(), K, C);
  };
  return force;
}

// A Python function as a force between two nodes (UserNodeForce::evaluate_pair):
// function(t, x, R, v, w, x_other, R_other, v_other, w_other) -> f (6) on the node, or with
// `jacobian` -> (f, K, C), K = df/d(x, theta, x_other, theta_other), C = df/d(v, omega, v_other,
// omega_other) (6 x 12).
femb::UserNodeForce PythonPairForce(const std::string& name, const py::object& function, bool jacobian) {
  const PythonFunction fn(name, function);
  femb::UserNodeForce force;
  force.name = name;
  using M = femb::UserNodeForce::Matrix6x12;
  force.evaluate_pair = [fn, jacobian](double t, const femb::UserForceMotion& a, const femb::UserForceMotion& b,
                                       femb::UserNodeForce::Vector6& f, M* K, M* C) {
    py::gil_scoped_acquire gil;
    return fn.TakeValue(
        t, fn.Call(t, a.x, a.R, a.v, a.w, b.x, b.R, b.v, b.w), jacobian, 6, 12,
        {kForceWhat, "K = df/d(x, theta, x_other, theta_other)", "C = df/d(v, omega, v_other, omega_other)"},
        "(f, K, C)", f.data(), K, C);
  };
  return force;
}

// A Python function as a UserModalForce: function(t, q, qdot) -> Q (n), or with `jacobian` ->
// (Q, K, C), K = dQ/dq, C = dQ/dqdot (n x n).
femb::UserModalForce PythonModalForce(const std::string& name, const py::object& function, bool jacobian) {
  const PythonFunction fn(name, function);
  femb::UserModalForce force;
  force.name = name;
  force.evaluate = [fn, jacobian](double t, const Eigen::VectorXd& q, const Eigen::VectorXd& qdot, Eigen::VectorXd& Q,
                                  Eigen::MatrixXd* K, Eigen::MatrixXd* C) {
    py::gil_scoped_acquire gil;
    const long n = q.size();
    Q.resize(n);
    return fn.TakeValue(t, fn.Call(t, q, qdot), jacobian, n, n,
                        {"the generalized force Q", "K = dQ/dq", "C = dQ/dqdot"}, "(Q, K, C)", Q.data(), K, C);
  };
  return force;
}

// The options of a run from Python: in memory unless `output`, the caller's words and forces.
femb::SolveRunOptions RunOptions(const std::string& output, int threads, const py::object& progress,
                                 const py::object& warning, const py::list& forces, const py::list& modal_forces) {
  femb::SolveRunOptions options;
  options.in_memory = output.empty();
  options.output = output;
  if (threads > 0) options.threads = threads;
  options.progress = LineSink(progress);
  options.warning = LineSink(warning);
  for (const py::handle item : forces) {
    const auto [node, other, force_name, function, jacobian] =
        item.cast<std::tuple<std::string, std::string, std::string, py::object, bool>>();
    options.user_forces.push_back({node, other,
                                   other.empty() ? PythonForce(force_name, function, jacobian)
                                                 : PythonPairForce(force_name, function, jacobian)});
  }
  for (const py::handle item : modal_forces) {
    const auto [body, force_name, function, jacobian] =
        item.cast<std::tuple<std::string, std::string, py::object, bool>>();
    options.user_modal_forces.push_back({body, PythonModalForce(force_name, function, jacobian)});
  }
  return options;
}

// A scene run: its results in memory, and in `output` when one is given.
struct RunResult {
  int exit_code = 0;
  std::string status, error;
  femb::RecordedResults results;
  Eigen::VectorXd frequencies_hz;
  std::string analysis;
  long steps = 0, iterations = 0;
  std::string output;                   ///< the run's output folder, or empty: kept in memory
  std::shared_ptr<femb::SolveRun> run;  ///< kept for the animation of a run kept in memory
};

// Ctrl-C in a dynamic run: every 64 steps (and at most every 0.1 s) the run takes the GIL and
// lets Python run its signal handlers; a KeyboardInterrupt (or any exception a handler raises)
// stops the run at the end of its step, its results kept in `output` when there is one, and is
// raised when the run returns.
class Interruption {
 public:
  void Check() {
    if (++steps_ % 64 != 0) return;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_ < std::chrono::milliseconds(100)) return;
    last_ = now;
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() == 0) return;
    error_.emplace();  // fetches the exception the handler raised
    stop_ = SIGINT;
  }
  const std::atomic<int>* stop() const { return &stop_; }
  // With the GIL held: the exception a handler raised, raised again.
  void RaiseIfInterrupted() {
    if (!error_) return;
    py::error_already_set error = std::move(*error_);
    error_.reset();
    throw error;
  }

 private:
  long steps_ = 0;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
  std::atomic<int> stop_{0};
  std::optional<py::error_already_set> error_;
};

RunResult Run(const std::string& text, const std::string& name, const std::vector<std::string>& overrides,
              const std::string& output, int threads, const py::object& progress, const py::object& warning,
              const py::list& forces, const py::list& modal_forces) {
  Interruption interruption;
  femb::SolveRunOptions options = RunOptions(output, threads, progress, warning, forces, modal_forces);
  options.stop = interruption.stop();
  options.after_step = [&interruption](const femb::DynamicState&) { interruption.Check(); };
  auto run = std::make_shared<femb::SolveRun>(femb::ParseScene(text, name, overrides), std::move(options));
  RunResult r;
  {
    py::gil_scoped_release release;
    r.exit_code = run->Run();
  }
  interruption.RaiseIfInterrupted();
  r.status = run->status();
  r.error = run->error();
  r.results = std::as_const(*run).recorder().Results();
  r.frequencies_hz = run->frequencies_hz();
  r.analysis = femb::Name(run->spec().analysis.type);
  r.steps = run->steps();
  r.iterations = run->iterations();
  r.output = output;
  if (output.empty()) r.run = std::move(run);
  return r;
}

// A dynamic run stepped under the caller's control: the run goes on a thread of its own and waits
// after each step that reaches the time asked for (StepTo), so that the caller reads the state
// (and changes what its forces read) between steps. The run is SolveRun's, the same steps and
// results as Run's to the bit. Each side hands over to the other by a flag it watches (yielding)
// for a while before it sleeps on the condition: a caller stepping at every step waits about one step
// (tens of microseconds) for the run, and the run waits for the caller's code between two
// step_to calls, both far shorter than putting a thread to sleep and waking it again.
class Simulation {
 public:
  Simulation(const std::string& text, const std::string& name, const std::vector<std::string>& overrides,
             const std::string& output, int threads, const py::object& progress, const py::object& warning,
             const py::list& forces, const py::list& modal_forces) {
    femb::SolveRunOptions options = RunOptions(output, threads, progress, warning, forces, modal_forces);
    options.stop = &stop_;
    options.after_step = [this](const femb::DynamicState& s) { Pause(s); };
    femb::SceneSpec spec = femb::ParseScene(text, name, overrides);
    if (spec.analysis.type != femb::AnalysisType::kDynamic) {
      throw femb::InputError(spec.file + ": start() steps a dynamic analysis; run() the " +
                             femb::Name(spec.analysis.type) + " one");
    }
    output_ = output;
    run_ = std::make_shared<femb::SolveRun>(std::move(spec), std::move(options));
  }
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;
  ~Simulation() { Close(); }

  /// Steps until the first step that ends at or after t (or the run's end); returns that time.
  double StepTo(double t) {
    {
      py::gil_scoped_release release;
      std::unique_lock<std::mutex> lock(mutex_);
      if (!done_) {
        target_ = t;
        if (!worker_.joinable()) {
          worker_ = std::thread([this] { Work(); });
        } else {
          paused_ = false;
          changed_.notify_all();
        }
        Await(lock, [this] { return paused_ || done_; });
      }
    }
    if (error_) std::rethrow_exception(error_);
    return time_;
  }
  /// Stops the run at its next step's end (its results so far kept) and waits for it.
  void Close() {
    py::gil_scoped_release release;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      if (!worker_.joinable()) return;
      if (!done_) {
        stop_ = SIGTERM;
        paused_ = false;
        changed_.notify_all();
      }
    }
    worker_.join();
  }
  double time() const { return time_; }
  bool done() const { return done_; }
  /// A node's position, rotation, velocity and angular velocity at the last pause (world axes).
  py::dict Node(const std::string& name) const {
    std::unique_lock<std::mutex> lock(mutex_);
    const femb::Scene& scene = run_->scene();
    const auto k = scene.node_index.find(name);
    if (k == scene.node_index.end()) throw femb::InputError("no node '" + name + "' in the scene");
    if (!has_state_) throw femb::InputError("no state yet: step_to() a time first");
    const femb::SystemState& c = state_.config;
    const Eigen::Matrix<double, 6, 1> motion = femb::NodeMotion(c, k->second, state_.W);
    py::dict out;
    out["position"] = Eigen::Vector3d(c.x[size_t(k->second)] + scene.origin);
    out["rotation"] = c.R[size_t(k->second)];
    out["velocity"] = Eigen::Vector3d(motion.head<3>());
    out["angular_velocity"] = Eigen::Vector3d(motion.tail<3>());
    return out;
  }
  /// The results so far (paused or done).
  RunResult Results() const {
    std::unique_lock<std::mutex> lock(mutex_);
    RunResult r;
    r.exit_code = done_ ? exit_code_ : 0;
    r.status = done_ ? run_->status() : "paused";
    r.error = run_->error();
    if (worker_.joinable() || done_) r.results = std::as_const(*run_).recorder().Results();
    r.analysis = femb::Name(run_->spec().analysis.type);
    r.steps = run_->steps();
    r.iterations = run_->iterations();
    r.output = output_;
    if (done_ && output_.empty()) r.run = run_;
    return r;
  }

 private:
  void Work() {
    int code = 1;
    std::exception_ptr error;
    try {
      code = run_->Run();
    } catch (...) {
      error = std::current_exception();
    }
    std::unique_lock<std::mutex> lock(mutex_);
    exit_code_ = code;
    error_ = error;
    done_ = true;
    changed_.notify_all();
  }
  // After each step: go on below the target; else keep the state for the caller and wait.
  void Pause(const femb::DynamicState& s) {
    std::unique_lock<std::mutex> lock(mutex_);
    time_ = s.t;
    const double slack = std::isfinite(target_) ? 1e-12 * std::max(1.0, std::abs(target_)) : 0.0;
    if (stop_ != 0 || s.t < target_ - slack) return;
    state_ = s;
    has_state_ = true;
    paused_ = true;
    changed_.notify_all();
    Await(lock, [this] { return !paused_; });
  }
  // Waits, holding `lock` on return, until ready() (which reads atomics only): up to kSpin with
  // the lock released, yielding the processor between looks (so that a loaded machine's other
  // threads run), then asleep on the condition. Measured on the 10-body slider-crank stepped at
  // every step: 50 us per pause with the condition alone, 3-5 us so.
  template <class Ready>
  void Await(std::unique_lock<std::mutex>& lock, Ready ready) {
    constexpr std::chrono::microseconds kSpin{200};
    if (ready()) return;
    lock.unlock();
    const auto until = std::chrono::steady_clock::now() + kSpin;
    bool done = false;
    while (!(done = ready()) && std::chrono::steady_clock::now() < until) std::this_thread::yield();
    lock.lock();
    if (!done) changed_.wait(lock, ready);
  }

  // Shared with the results of a finished run kept in memory, for its animation (the run's
  // callbacks into this object are not called after the run).
  std::shared_ptr<femb::SolveRun> run_;
  std::string output_;
  std::thread worker_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::atomic<int> stop_{0};
  double target_ = 0.0, time_ = 0.0;
  std::atomic<bool> paused_{false}, done_{false};
  bool has_state_ = false;
  int exit_code_ = 0;
  std::exception_ptr error_;
  femb::DynamicState state_;
};

void BindResults(py::module_& m) {
  using B = femb::RecordedResults::Body;
  py::class_<B>(m, "BodySeries")
      .def_readonly("name", &B::name)
      .def_readonly("nodes", &B::nodes)
      .def_readonly("modal_coordinates", &B::modal_coordinates)
      .def_readonly("floating_frame", &B::floating_frame)
      .def_readonly("center_of_mass", &B::center_of_mass)
      .def_readonly("max_von_mises", &B::max_von_mises)
      .def_readonly("max_von_mises_node", &B::max_von_mises_node)
      .def_readonly("max_von_mises_point", &B::max_von_mises_point);
  using R = femb::RecordedResults;
  py::class_<R>(m, "RecordedResults")
      .def_readonly("time", &R::time)
      .def_readonly("step_size", &R::step_size)
      .def_readonly("probe_names", &R::probe_names)
      .def_readonly("probes", &R::probes)
      .def_readonly("steps_time", &R::steps_time)
      .def_readonly("steps_size", &R::steps_size)
      .def_readonly("steps_taken", &R::steps_taken)
      .def_readonly("rejected_by_error", &R::rejected_by_error)
      .def_readonly("newton_cuts", &R::newton_cuts)
      .def_readonly("cut_joints", &R::cut_joints)
      .def_readonly("loop_violation", &R::loop_violation)
      .def_readonly("loop_reaction", &R::loop_reaction)
      .def_readonly("node_names", &R::node_names)
      .def_readonly("position", &R::position)
      .def_readonly("quaternion", &R::quaternion)
      .def_readonly("velocity", &R::velocity)
      .def_readonly("angular_velocity", &R::angular_velocity)
      .def_readonly("reaction", &R::reaction)
      .def_readonly("joint_coordinate_labels", &R::joint_coordinate_labels)
      .def_readonly("joint_coordinates", &R::joint_coordinates)
      .def_readonly("kinetic", &R::kinetic)
      .def_readonly("elastic", &R::elastic)
      .def_readonly("external_work", &R::external_work)
      .def_readonly("linear_momentum", &R::linear_momentum)
      .def_readonly("angular_momentum", &R::angular_momentum)
      .def_readonly("bodies", &R::bodies);
  py::class_<RunResult>(m, "RunResult")
      .def_readonly("exit_code", &RunResult::exit_code)
      .def_readonly("status", &RunResult::status)
      .def_readonly("error", &RunResult::error)
      .def_readonly("results", &RunResult::results)
      .def_readonly("frequencies_hz", &RunResult::frequencies_hz)
      .def_readonly("analysis", &RunResult::analysis)
      .def_readonly("steps", &RunResult::steps)
      .def_readonly("iterations", &RunResult::iterations)
      .def_readonly("output", &RunResult::output)
      .def("write_animation", [](RunResult& r, const std::string& directory) {
        // A run kept in memory: its animation made from the frames kept (holding the GIL: one
        // call at a time on the run's recorder). False: none kept.
        if (!r.run) return false;
        r.run->WriteAnimation(directory);
        return true;
      });
}

void BindSuperelement(py::module_& m) {
  py::class_<femb::MassProperties>(m, "MassProperties")
      .def_readonly("mass", &femb::MassProperties::mass)
      .def_readonly("center_of_mass", &femb::MassProperties::center_of_mass)
      .def_readonly("inertia_com", &femb::MassProperties::inertia_com);
  py::class_<femb::InterfaceNode>(m, "InterfaceNode")
      .def_readonly("name", &femb::InterfaceNode::name)
      .def_readonly("position", &femb::InterfaceNode::position)
      .def_readonly("orientation", &femb::InterfaceNode::orientation);
  using S = femb::Superelement;
  py::class_<S>(m, "SuperelementData")
      .def_readonly("name", &S::name)
      .def_readonly("K", &S::K)
      .def_readonly("M", &S::M)
      .def_readonly("interfaces", &S::interfaces)
      .def_readonly("internal_frequencies_hz", &S::internal_frequencies_hz)
      .def_readonly("full_free_free_frequencies_hz", &S::full_free_free_frequencies_hz)
      .def_property_readonly("n_reduced_dofs", &S::n_reduced_dofs)
      .def_property_readonly("labels",
                             [](const S& se) {
                               std::vector<std::string> labels;
                               for (int i = 0; i < se.n_reduced_dofs(); ++i)
                                 labels.push_back(femb::ReducedCoordinateLabel(se, i));
                               return labels;
                             })
      .def_property_readonly("mass_properties", &femb::ComputeMassProperties)
      .def_property_readonly("has_mesh", [](const S& se) { return se.visualization.has_value(); })
      .def_property_readonly("mesh_nodes",
                             [](const S& se) { return se.visualization ? se.visualization->nodes : Eigen::MatrixXd(); })
      .def_property_readonly("mesh_cells",
                             [](const S& se) { return se.visualization ? se.visualization->cells : Eigen::MatrixXi(); })
      .def_property_readonly("mesh_dofs_per_node",
                             [](const S& se) { return se.visualization ? se.visualization->dofs_per_node : 0; })
      .def_property_readonly(
          "mesh_shapes", [](const S& se) { return se.visualization ? se.visualization->shapes : Eigen::MatrixXd(); })
      .def("checks_json", [](const S& se) { return femb::JsonSummary(se, femb::AnalyzeSuperelement(se)).dump(); })
      .def("write_vtu", &femb::WriteModeShapesVtu);
  m.def("read_superelement", [](const std::string& path) { return femb::ReadSuperelementFile(path); });
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "femb's C++ core; use the package femb.";
  static py::exception<femb::InputError> femb_error(m, "FembError", PyExc_RuntimeError);
  static py::exception<femb::InputError> input_error(m, "InputError", femb_error.ptr());
  static py::exception<std::runtime_error> numerical_error(m, "NumericalError", femb_error.ptr());
  static py::exception<std::runtime_error> refused_error(m, "RefusedError", femb_error.ptr());
  g_numerical_error = numerical_error.ptr();
  g_refused_error = refused_error.ptr();
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const femb::InputError& e) {
      PyErr_SetString(input_error.ptr(), e.what());
    } catch (const femb::ResourceLimitError& e) {
      PyErr_SetString(refused_error.ptr(), e.what());
    }
  });
  BindSuperelement(m);
  BindResults(m);
  m.def("reduce", &Reduce, py::arg("text"), py::arg("name"), py::arg("overrides"), py::arg("output"),
        py::arg("progress"), py::arg("warning"));
  m.def("run", &Run, py::arg("text"), py::arg("name"), py::arg("overrides"), py::arg("output"), py::arg("threads"),
        py::arg("progress"), py::arg("warning"), py::arg("forces"), py::arg("modal_forces"));
  py::class_<Simulation>(m, "Simulation")
      .def(py::init<const std::string&, const std::string&, const std::vector<std::string>&, const std::string&, int,
                    const py::object&, const py::object&, const py::list&, const py::list&>())
      .def("step_to", &Simulation::StepTo)
      .def("close", &Simulation::Close)
      .def_property_readonly("time", &Simulation::time)
      .def_property_readonly("done", &Simulation::done)
      .def("node", &Simulation::Node)
      .def("results", &Simulation::Results);
  m.def("write_results", &femb::WriteResultsFile, py::arg("results"), py::arg("status"), py::arg("path"));
  m.def("write_probes_csv", &femb::WriteProbesCsv, py::arg("results"), py::arg("path"));
  m.def("check_scene", [](const std::string& text, const std::string& name, const std::vector<std::string>& overrides) {
    femb::ParseScene(text, name, overrides);
  });
  m.def("check_part", [](const std::string& text, const std::string& name, const std::vector<std::string>& overrides) {
    femb::ParsePart(text, name, overrides);
  });
}
