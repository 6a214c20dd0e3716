#include "solver/run/solve_run.h"

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdarg>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>

#include "formats/input_error.h"
#include "solver/analysis/modal_analysis.h"
#include "solver/analysis/static_analysis.h"
#include "solver/analysis/step_control.h"
#include "solver/output/checkpoint.h"

namespace femb {
namespace {

StaticOptions StaticOptionsOf(const SceneAnalysisSpec& a) {
  StaticOptions options;
  options.end_time = a.end_time;
  options.steps = a.steps;
  options.tolerance = a.tolerance;
  options.max_iterations = a.max_iterations;
  return options;
}

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The mode shapes as output steps 1..n after the state (step 0): each the state moved along the
// mode by an amplitude that displaces its largest-moving node by 5% of the scene's size (the
// time value of step k is the mode number k). Shown by the animation and kept in results.h5.
void RecordModeShapes(const Scene& scene, const SystemState& state, const ModalResult& modes, double load_time,
                      ResultsRecorder& recorder) {
  const SystemModel& model = scene.model;
  const DofMap& dofs = model.dofs();
  const double size = model.n_nodes() > 1 ? BoundingDiagonal(state.x) : 1.0;
  for (int k = 0; k < modes.shapes.cols(); ++k) {
    const Eigen::VectorXd v = modes.shapes.col(k);
    double largest = 0.0;
    for (int n = 0; n < model.n_nodes(); ++n) largest = std::max(largest, NodeMotion(state, n, v).head<3>().norm());
    if (!(largest > 0)) continue;  // a mode of modal coordinates or rotations only: no motion to show
    SystemState moved = state;
    ApplyIncrement(model, dofs, (0.05 * size / largest) * v, moved);
    UpdateKinematics(model, dofs, moved);
    const SystemForces f = AssembleStatic(model, dofs, moved, load_time, false);  // solves the frames
    if (!f.ok) continue;
    recorder.Record(double(k + 1), moved, Eigen::VectorXd(), 0.0, 0.0, 0.0);
  }
}

// A static state as a checkpoint's: the configuration at load factor t, at rest.
DynamicState AtRest(const SystemState& config, double t) {
  DynamicState s;
  s.config = config;
  s.t = t;
  return s;
}

// The scene with the caller's forces on its nodes (one line for a node it does not have).
Scene WithUserForces(Scene scene, const std::vector<UserForceSpec>& forces,
                     const std::vector<UserModalForceSpec>& modal_forces) {
  for (const UserModalForceSpec& spec : modal_forces) {
    const auto b = std::find(scene.body_names.begin(), scene.body_names.end(), spec.body);
    const std::string where = scene.spec.file + ": modal force '" + spec.force.name + "': ";
    if (b == scene.body_names.end()) throw InputError(where + "no body '" + spec.body + "' in the scene");
    UserModalForce force = spec.force;
    force.body = int(b - scene.body_names.begin());
    if (scene.model.bodies[size_t(force.body)].n_modes() == 0) {
      throw InputError(where + "body '" + spec.body + "' has no modal coordinates");
    }
    scene.model.user_modal_forces.push_back(std::move(force));
  }
  for (const UserForceSpec& spec : forces) {
    const auto k = scene.node_index.find(spec.node);
    if (k == scene.node_index.end()) {
      throw InputError(scene.spec.file + ": force '" + spec.force.name + "': no node '" + spec.node + "' in the scene");
    }
    UserNodeForce force = spec.force;
    force.node = k->second;
    if (!spec.other.empty()) {
      const auto other = scene.node_index.find(spec.other);
      if (other == scene.node_index.end() || other->second == k->second) {
        throw InputError(scene.spec.file + ": force '" + spec.force.name + "': no other node '" + spec.other +
                         "' in the scene (a force between two nodes needs two)");
      }
      force.other = other->second;
    }
    scene.model.user_forces.push_back(std::move(force));
  }
  return scene;
}

}  // namespace

SolveRun::SolveRun(SceneSpec spec, SolveRunOptions options)
    : options_(std::move(options)),
      wall_(options_.started),
      spec_(std::move(spec)),
      scene_(WithUserForces(BuildScene(spec_), options_.user_forces, options_.user_modal_forces)) {}

void SolveRun::Say(const char* format, ...) const {
  if (!options_.progress) return;
  char buffer[1024];
  va_list args;
  va_start(args, format);
  std::vsnprintf(buffer, sizeof buffer, format, args);
  va_end(args);
  options_.progress(buffer);
}

std::string SolveRun::Kept() const {
  return options_.in_memory ? "; the results up to it are kept" : "; results up to it are in " + options_.output;
}

void SolveRun::Warn(const std::string& line) const {
  if (options_.warning) options_.warning("warning: " + line);
}

int SolveRun::Run() {
  ReadRestart();
  ReadInitialState();
  recorder_.emplace(scene_, options_.output);
  if (resume_) ResumeRecorder();
  read_seconds_ = Seconds(wall_);  // scene, superelement files, model
  if (!quiet()) PrintSummary();
  try {
    if (spec_.analysis.type == AnalysisType::kModes) return RunModes();
    if (spec_.analysis.type == AnalysisType::kStatic) {
      RunStatic();
    } else {
      RunDynamic();
    }
  } catch (const UserForceError& e) {
    // A user function failed (raised, NaN, a wrong shape): a numerical failure with the results
    // recorded up to it; the state it failed in is no state to continue from.
    ok_ = false;
    status_ = e.what();
    no_checkpoint_ = true;
  }
  return Finish();
}

// --restart: what the stopped run carries into its next step, read and checked.
void SolveRun::ReadRestart() {
  const std::string& restart = options_.restart;
  if (!restart.empty()) {
    if (!options_.output.empty() && std::filesystem::path(options_.output) != std::filesystem::path(restart)) {
      throw InputError("--restart " + restart + " continues the run in that folder; leave out -o " + options_.output);
    }
    options_.output = restart;
  }
  if (options_.in_memory) {
    if (!restart.empty())
      throw InputError("restart " + restart + ": continues a run written to files; give an output folder");
    options_.output.clear();
    return;
  }
  if (options_.output.empty()) options_.output = "out/" + spec_.name;
  if (restart.empty()) return;
  const std::string checkpoint = (std::filesystem::path(restart) / "checkpoint.h5").string();
  if (spec_.analysis.type != AnalysisType::kDynamic) {
    throw InputError("--restart " + restart +
                     ": continues dynamic analyses only (start one from a static run's "
                     "state with initial_state)");
  }
  resume_.emplace();
  if (!ReadResume(restart, scene_, Signature(), *resume_)) {
    throw InputError(checkpoint +
                     ": holds no dynamic run to continue (a static run's state, or one written "
                     "before the first step: start anew, or from it with initial_state)");
  }
  if (!(spec_.analysis.end_time > resume_->state.t + 1e-12 * std::abs(spec_.analysis.end_time))) {
    char buffer[300];
    std::snprintf(buffer, sizeof buffer,
                  ": the run reached t = %.9g; analysis.end_time %.9g is not later (--set analysis.end_time=... "
                  "extends it)",
                  resume_->state.t, spec_.analysis.end_time);
    throw InputError(checkpoint + buffer);
  }
}

// initial_state: the state another run reached, read and checked against this model (a
// restarted run began from it already).
void SolveRun::ReadInitialState() {
  if (spec_.initial_state.from.empty() || resume_) return;
  const SceneSpec::InitialStateSpec& is = spec_.initial_state;
  if (spec_.analysis.type == AnalysisType::kStatic) {
    throw InputError(is.where +
                     ": initial_state: a static analysis starts from the model's placement (give it "
                     "to a dynamic or modes analysis)");
  }
  if (!spec_.initial_velocities.empty() || !spec_.initial_joint_rates.empty()) {
    throw InputError(is.where + ": initial_state: the velocities are the state's; leave out initial_velocity");
  }
  std::filesystem::path dir(is.from);
  if (dir.is_relative()) dir = std::filesystem::path(spec_.file).parent_path() / dir;
  AnalysisType kind = AnalysisType::kStatic;
  from_ = ReadCheckpoint(dir.string(), scene_, Signature(), &kind);
  t0_ = is.time ? *is.time : kind == AnalysisType::kDynamic ? from_->t : 0.0;
  if (spec_.analysis.type == AnalysisType::kDynamic && !(spec_.analysis.end_time > t0_)) {
    char buffer[200];
    std::snprintf(buffer, sizeof buffer, ": analysis.end_time %.6g is not after the initial state's time %.6g",
                  spec_.analysis.end_time, t0_);
    throw InputError(is.where + buffer);
  }
  if (!quiet()) {
    Say("initial state: the %s state of %s at t = %.6g, started at t = %.6g", Name(kind), dir.string().c_str(),
        from_->t, t0_);
  }
}

// The results and this program's counts of the run that --restart continues.
void SolveRun::ResumeRecorder() {
  const h5::Reader checkpoint((std::filesystem::path(options_.restart) / "checkpoint.h5").string());
  recorder().Resume(checkpoint);
  recorder().ResumedAt(resume_->state.t);
  const Eigen::VectorXd run = checkpoint.Vector("/run/counts");
  if (run.size() != 2) throw InputError(checkpoint.path() + ": /run/counts must hold 2 values");
  step_count_ = long(run[0]), total_iterations_ = long(run[1]);
  if (!quiet()) {
    Say("restart: %s at t = %.6g (%ld steps, %ld output steps), to t = %.6g", options_.restart.c_str(),
        resume_->state.t, step_count_, recorder().steps(), spec_.analysis.end_time);
  }
}

// The model's size, which inertia and stiffening the flexible bodies use, and the notes (one
// per file, not per body) that say why when a body does without either.
void SolveRun::PrintSummary() const {
  const int threads = options_.threads;
  Say("%s: %zu bodies, %d nodes, %d unknowns, %s analysis%s", spec_.file.c_str(), scene_.model.bodies.size(),
      scene_.model.n_nodes(), scene_.model.dofs().n_dofs(), Name(spec_.analysis.type),
      spec_.analysis.type == AnalysisType::kDynamic
          ? (", " + std::to_string(threads) + (threads == 1 ? " thread" : " threads")).c_str()
          : "");
  int flexible = 0, exact = 0, stiffened = 0;
  for (const SuperelementBody& body : scene_.model.bodies) {
    if (body.n_coordinates() <= 6) continue;
    ++flexible;
    exact += body.has_exact_inertia();
    stiffened += body.options().geometric_stiffening && body.has_inertia_stiffening();
  }
  if (flexible > 0) {
    Say("%d flexible bodies: %d with the exact inertia, %d with the corotational one; %d "
        "with geometric stiffening, %d linear inside",
        flexible, exact, flexible - exact, stiffened, flexible - stiffened);
  }
  std::set<std::string> said;
  for (const std::string& note : scene_.notes) {
    const std::string file = note.substr(note.find(": ") + 2);
    if (said.insert(file).second) Say("note: %s", note.c_str());
  }
}

// What a restart continues from, at an output step or the last step: the run's state and what
// it carries into its next step, with the results' mark and this program's counts there.
void SolveRun::Take(const DynamicStepReport& report) {
  if (!saved_) saved_.emplace();
  (*report.capture)(*saved_);
  mark_ = recorder().TakeMark();
  saved_steps_ = step_count_, saved_iterations_ = total_iterations_;
}
// The model's signature (ModelSignature: it re-reads and hashes every superelement file), made
// once, when a checkpoint is first read or written: a run kept in memory that starts from no
// saved state never makes it.
const std::string& SolveRun::Signature() {
  if (signature_.empty()) signature_ = ModelSignature(scene_);
  return signature_;
}
void SolveRun::SaveCheckpoint(const DynamicState& state) {
  if (options_.in_memory || no_checkpoint_) return;
  const AnalysisType kind = is_static() ? AnalysisType::kStatic : AnalysisType::kDynamic;
  if (!saved_) return WriteCheckpoint(options_.output, scene_, Signature(), state, kind);
  WriteCheckpoint(options_.output, scene_, Signature(), saved_->state, kind, &*saved_, [&](h5::Writer& w) {
    recorder().WriteMark(w, mark_);
    w.CreateGroup("/run");
    w.Vector("/run/counts", Eigen::Vector2d(double(saved_steps_), double(saved_iterations_)));
  });
}
// Results on disk during the run (when due, or now with `force`): results.h5's status says how
// far it got; the checkpoint follows the results it refers to.
void SolveRun::Flush(const DynamicState& state, bool force, const DynamicStepReport* report) {
  if (!force && !recorder().FlushDue()) return;
  char running[160];
  std::snprintf(running, sizeof running, "running: %s %.6g of %.6g (written during the run)",
                is_static() ? "load factor" : "t =", state.t, spec_.analysis.end_time);
  if (report) Take(*report);
  const double start = Seconds(wall_);
  recorder().Flush(running);
  SaveCheckpoint(state);
  run_write_seconds_ += Seconds(wall_) - start;
}
// A progress line at most once a second (or now with `force`), with the largest violation of
// the closed loops' equations so far (a length).
void SolveRun::Progress(double t, bool force) {
  if (quiet()) return;
  if (!force && Seconds(wall_) - last_print_ < 1.0) return;
  last_print_ = Seconds(wall_);
  char loops[64] = "";
  if (scene_.model.has_constraints())
    std::snprintf(loops, sizeof loops, " loop gap %.2g", recorder().max_loop_violation());
  if (spec_.analysis.adaptive_step) {
    Say("t = %-10.6g steps %-7ld rejected %-5ld Newton iterations %-8ld wall %.2f s%s", t, step_count_, rejected_,
        total_iterations_, Seconds(wall_), loops);
  } else {
    Say("t = %-10.6g steps %-7ld Newton iterations %-8ld wall %.2f s%s", t, step_count_, total_iterations_,
        Seconds(wall_), loops);
  }
}

// analysis.type modes: the linearized modes about the initial (or static) state, their shapes
// as output steps, the frequencies in modes.csv. The exit code.
int SolveRun::RunModes() {
  SystemState state = from_ ? from_->config : InitialState(scene_.model);
  double load_time = t0_;
  if (spec_.analysis.modes_about_static && !from_) {
    const StaticResult r = SolveStatic(scene_.model, state, StaticOptionsOf(spec_.analysis));
    if (!r.ok) {
      recorder().Finish(r.message);
      error_ = spec_.file + ": numerical failure in the static state for the modes: " + r.message;
      return 3;
    }
    load_time = spec_.analysis.end_time;
  }
  recorder().Record(load_time, state, Eigen::VectorXd(), 0.0, 0.0, 0.0);
  const ModalResult modes = LinearizedModes(scene_.model, state, load_time, spec_.analysis.mode_count);
  if (modes.ok) RecordModeShapes(scene_, state, modes, load_time, recorder());
  recorder().Finish(modes.ok ? "completed" : modes.message);
  if (!modes.ok) {
    error_ = spec_.file + ": numerical failure: " + modes.message;
    return 3;
  }
  frequencies_hz_ = modes.frequencies_hz;
  if (options_.in_memory) {
    for (int k = 0; k < modes.frequencies_hz.size(); ++k) Say("mode %3d  %14.6g Hz", k + 1, modes.frequencies_hz[k]);
    return 0;
  }
  const std::string path = options_.output + "/modes.csv";
  {
    std::ofstream out(path + ".tmp");
    out << "mode,frequency_hz\n";
    for (int k = 0; k < modes.frequencies_hz.size(); ++k) {
      out << k + 1 << "," << modes.frequencies_hz[k] << "\n";
      if (!quiet()) Say("mode %3d  %14.6g Hz", k + 1, modes.frequencies_hz[k]);
    }
  }
  std::rename((path + ".tmp").c_str(), path.c_str());
  if (!quiet()) Say("frequencies in %s", path.c_str());
  return 0;
}

// The joints' reactions at a static state, when the scene asks for them: from the converged
// pass's node forces when given, else from an assembly at the state.
std::vector<Eigen::Matrix<double, 6, 1>> SolveRun::StaticReactions(double lambda, const SystemState& st,
                                                                   const NodeForces* converged) const {
  std::vector<Eigen::Matrix<double, 6, 1>> out;
  if (!spec_.reactions) return out;
  if (converged) return JointReactions(scene_.model, scene_.model.dofs(), st, *converged);
  SystemState copy = st;
  const SystemForces f = AssembleStatic(scene_.model, scene_.model.dofs(), copy, lambda, false);
  return JointReactions(scene_.model, scene_.model.dofs(), copy, f.node_forces);
}

// analysis.type static: load stepping, recording every output_every-th step.
void SolveRun::RunStatic() {
  SystemState state = InitialState(scene_.model);
  const auto reactions0 = StaticReactions(0.0, state);
  recorder().Record(0.0, state, Eigen::VectorXd(), 0.0, 0.0, 0.0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                    spec_.reactions ? &reactions0 : nullptr);
  Flush(AtRest(state, 0.0), true);
  StaticOptions static_options = StaticOptionsOf(spec_.analysis);
  static_options.stop = options_.stop;
  static_options.threads = options_.threads;
  const StaticResult r =
      SolveStatic(scene_.model, state, static_options, [&](const StaticStepReport& s, const SystemState& st) {
        ++step_count_;
        total_iterations_ += s.iterations;
        if (step_count_ % spec_.analysis.output_every == 0) {
          const auto reactions = StaticReactions(s.lambda, st, s.node_forces);
          recorder().Record(s.lambda, st, Eigen::VectorXd(), 0.0, s.elastic_energy, s.external_work,
                            Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), spec_.reactions ? &reactions : nullptr);
          if (recorder().FlushDue()) Flush(AtRest(st, s.lambda), true);
        }
        Progress(s.lambda, false);
      });
  ok_ = r.ok;
  if (!ok_) status_ = r.message;
  stopped_ = r.stopped;
  stopped_at_ = r.steps.empty() ? 0.0 : r.steps.back().lambda;
  final_state_ = AtRest(state, stopped_at_);
  for (const std::string& w : r.warnings) Warn(w);
}

// The dynamic analysis' options from the scene's analysis and the command line.
DynamicOptions SolveRun::DynamicOptionsOf() {
  const SceneAnalysisSpec& a = spec_.analysis;
  DynamicOptions options;
  options.step = a.step;
  options.end_time = a.end_time;
  options.rho_inf = a.rho_inf;
  options.integrator = a.integrator;
  options.tolerance = a.tolerance;
  options.max_iterations = a.max_iterations;
  options.jacobian_reuse = a.jacobian_reuse;  // unset: the integrator's (JacobianReuseOf)
  options.full_inertia_tangent = a.gyroscopic_tangent;
  if (a.body_matrices_every > 0) options.body_matrices_every = a.body_matrices_every;
  options.body_matrices_kept = a.body_matrices_kept;
  options.threads = options_.threads;
  options.stop = options_.stop;
  if (resume_) options.resume = &*resume_;
  options.adaptive = a.adaptive_step;
  if (options.adaptive) options.step = 1e-4 * a.end_time;  // the first step tried
  options.step_tolerance = a.step_tolerance;
  options.min_step = a.min_step;
  options.max_step = a.max_step;
  options.output_step = a.output_step;
  for (const auto& [name, f] : spec_.functions) {
    for (double t : f.Breakpoints()) options.breakpoints.push_back(t);
  }
  return options;
}

// The state a dynamic run starts from: the checkpoint's (--restart), another run's
// (initial_state) or the placement with the scene's initial velocities; recorded unless resumed.
DynamicState SolveRun::InitialDynamicState() {
  if (resume_) return resume_->state;
  DynamicState state =
      from_ ? femb::InitialDynamicState(scene_.model, from_->config,
                                        from_->W.size() ? from_->W : scene_.initial_velocity, t0_)
            : femb::InitialDynamicState(scene_.model, InitialState(scene_.model), scene_.initial_velocity);
  const DynamicStepReport r0 = Measure(scene_.model, state);
  const auto reactions0 =
      spec_.reactions ? DynamicReactions(scene_.model, state) : std::vector<Eigen::Matrix<double, 6, 1>>();
  recorder().Record(state.t, state.config, state.W, r0.kinetic_energy, r0.elastic_energy, 0.0, r0.linear_momentum,
                    r0.angular_momentum, spec_.reactions ? &reactions0 : nullptr, &state.Wdot);
  recorder().RecordStepSize(0.0);
  Flush(state, true);
  return state;
}

// analysis.type dynamic: time stepping, recording at output_step's times (adaptive steps land
// on them) or every output_every-th step.
void SolveRun::RunDynamic() {
  DynamicState state = InitialDynamicState();
  const DynamicOptions options = DynamicOptionsOf();
  if (options.adaptive && options.integrator == Integrator::kMidpoint && !(options.max_step > 0)) {
    const double h = MidpointResolvedStep(scene_.model);
    if (h < 0.01 * (options.end_time - state.t)) {
      Say("note: step: auto under the midpoint scheme keeps its steps at or below %.3g s, which resolve the "
          "bodies' highest mode (%.4g Hz; the scheme damps none); analysis.max_step allows longer steps, with "
          "that mode ringing undamped in the reactions and stresses",
          h, 0.7 / h / (2 * M_PI));
    }
  }
  DynamicState output_state;
  const DynamicResult r =
      SolveDynamic(scene_.model, state, options, [&](const DynamicStepReport& s, const DynamicState& st) {
        ++step_count_;
        total_iterations_ += s.iterations;
        rejected_ = s.rejected;
        recorder().RecordStep(s.t, s.h);
        if (spec_.analysis.output_step > 0 ? s.output : step_count_ % spec_.analysis.output_every == 0) {
          // Reactions from the output state's consistent accelerations and multipliers, not
          // from the integrator's own (WithConsistentAccelerations); where those are the
          // integrator's own, from its converged pass's node forces.
          const bool converged_pass = s.node_forces && AccelerationsConsistent(scene_.model, st);
          const DynamicState& out =
              spec_.reactions && !converged_pass ? (output_state = WithConsistentAccelerations(scene_.model, st)) : st;
          std::vector<Eigen::Matrix<double, 6, 1>> reactions;
          if (spec_.reactions && converged_pass) {
            reactions = JointReactions(scene_.model, scene_.model.dofs(), st.config, *s.node_forces);
          } else if (spec_.reactions) {
            reactions = DynamicReactions(scene_.model, out);
          }
          recorder().Record(s.t, out.config, out.W, s.kinetic_energy, s.elastic_energy, s.external_work,
                            s.linear_momentum, s.angular_momentum, spec_.reactions ? &reactions : nullptr, &out.Wdot);
          recorder().RecordStepSize(s.h);
          Flush(st, false, &s);
        }
        if (s.last) Take(s);
        Progress(s.t, false);
        if (options_.after_step) options_.after_step(st);
      });
  ok_ = r.ok;
  if (!ok_) status_ = r.message;
  stopped_ = r.stopped;
  stopped_at_ = state.t;
  final_state_ = state;
  for (const std::string& w : r.warnings) Warn(w);
  if (!quiet()) PrintDynamicCounts(r, options);
  recorder().StepCounts(r.steps, r.rejected_by_error, r.newton_cuts);
}

// The factorizations, the bodies' matrices and, with error-controlled steps, the steps'
// statistics.
void SolveRun::PrintDynamicCounts(const DynamicResult& r, const DynamicOptions& options) const {
  const std::string analysed = r.pattern_analyses == 1 ? "once" : std::to_string(r.pattern_analyses) + " times";
  Say("%ld factorizations of the iteration matrix; its sparsity pattern analysed %s; pivots "
      "chosen in %ld, reused in %ld",
      r.factorizations, analysed.c_str(), r.pivoted, r.factorizations - r.pivoted);
  if (r.body_matrices_turned > 0 && options.integrator == Integrator::kRadau && options.body_matrices_every == 1) {
    Say("bodies' mass and gyroscopic matrices computed %ld times (at each matrix build's first stage), turned with "
        "their floating frames to the other stages %ld times",
        r.body_matrices_computed, r.body_matrices_turned);
  } else if (r.body_matrices_turned > 0) {
    const bool all = options.body_matrices_kept == BodyMatricesKept::kAll;
    Say("bodies' %smatrices computed %ld times, turned with their floating frames %ld times "
        "(analysis.body_matrices_every %d, body_matrices_kept %s)",
        all ? "" : "inertia ", r.body_matrices_computed, r.body_matrices_turned, options.body_matrices_every,
        all ? "all" : "inertia");
  }
  if (!spec_.analysis.adaptive_step) return;
  Say("%ld steps rejected (%ld by the error test, %ld by Newton)", r.rejected_by_error + r.newton_cuts,
      r.rejected_by_error, r.newton_cuts);
  if (r.steps > 0) {
    Say("steps: smallest %.3g s (ending at t = %.6g), largest %.3g s, mean %.3g s; every step "
        "in results.h5 /steps",
        r.smallest_step, r.smallest_step_time, r.largest_step, spec_.analysis.end_time / double(r.steps));
  }
}

// The results' status and the checkpoint written, the stresses summarized; the exit code.
int SolveRun::Finish() {
  const double solve_end = Seconds(wall_);
  const char* signal_name = stopped_ == SIGINT ? "SIGINT" : stopped_ == SIGTERM ? "SIGTERM" : "a signal";
  if (stopped_) {
    char buffer[200];
    std::snprintf(buffer, sizeof buffer, "stopped by %s at %s %.6g of %.6g", signal_name,
                  is_static() ? "load factor" : "t =", stopped_at_, spec_.analysis.end_time);
    status_ = buffer;
  }
  recorder().Finish(status_);
  // The checkpoint after the results it refers to (a kill between the two leaves the older one).
  SaveCheckpoint(final_state_);
  if (!stopped_) Progress(spec_.analysis.end_time, true);
  if (!quiet()) {
    for (const std::string& line : recorder().StressSummary()) Say("%s", line.c_str());
  }
  if (stopped_) {
    error_ = spec_.file + ": " + status_ + Kept();
    return 128 + stopped_;
  }
  if (!ok_) {
    error_ = spec_.file + ": numerical failure: " + status_ + Kept();
    return 3;
  }
  if (quiet()) return 0;
  if (recorder().flushes() > 0) {
    const std::string times = recorder().flushes() == 1 ? "once" : std::to_string(recorder().flushes()) + " times";
    Say("results written %s during the run (outputs.flush_every %g s), %.3f s in all", times.c_str(), spec_.flush_every,
        recorder().flush_seconds());
  }
  // The phases: reading (scene, superelement files, model), the analysis with its per-step
  // recording, writing results.h5, the checkpoint and the animation (at the end and during the
  // run: the files written during the run count as writing, not as solving).
  const double end = Seconds(wall_);
  Say("done in %.2f s (reading %.3f s, solving %.3f s, writing %.3f s): %ld steps, %.2f "
      "Newton iterations per step; %s",
      end, read_seconds_, solve_end - read_seconds_ - run_write_seconds_, end - solve_end + run_write_seconds_,
      step_count_, step_count_ ? double(total_iterations_) / step_count_ : 0.0,
      options_.in_memory ? "results in memory"
                         : ("results in " + recorder().h5_path() + ", " + recorder().csv_path()).c_str());
  return 0;
}

}  // namespace femb
