// femb-solve: simulate a scene of superelements (static or dynamic).
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "formats/command_line.h"
#include "formats/input_error.h"
#include "formats/scene_file.h"
#include "solver/analysis/dynamic_analysis.h"
#include "solver/analysis/modal_analysis.h"
#include "solver/analysis/static_analysis.h"
#include "solver/output/checkpoint.h"
#include "solver/output/results_recorder.h"
#include "solver/parallel.h"
#include "solver/scene/scene_builder.h"
#include "solver/stop_request.h"

namespace {

femb::StaticOptions StaticOptionsOf(const femb::SceneAnalysisSpec& a) {
  femb::StaticOptions options;
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
void RecordModeShapes(const femb::Scene& scene, const femb::SystemState& state, const femb::ModalResult& modes,
                      double load_time, femb::ResultsRecorder& recorder) {
  const femb::SystemModel& model = scene.model;
  const femb::DofMap& dofs = model.dofs();
  const double size = model.n_nodes() > 1 ? femb::BoundingDiagonal(state.x) : 1.0;
  for (int k = 0; k < modes.shapes.cols(); ++k) {
    const Eigen::VectorXd v = modes.shapes.col(k);
    double largest = 0.0;
    for (int n = 0; n < model.n_nodes(); ++n)
      largest = std::max(largest, femb::NodeMotion(state, n, v).head<3>().norm());
    if (!(largest > 0)) continue;  // a mode of modal coordinates or rotations only: no motion to show
    femb::SystemState moved = state;
    femb::ApplyIncrement(model, dofs, (0.05 * size / largest) * v, moved);
    femb::UpdateKinematics(model, dofs, moved);
    const femb::SystemForces f = femb::AssembleStatic(model, dofs, moved, load_time, false);  // solves the frames
    if (!f.ok) continue;
    recorder.Record(double(k + 1), moved, Eigen::VectorXd(), 0.0, 0.0, 0.0);
  }
}

constexpr const char* kUsage =
    R"(usage: femb-solve SCENE.yaml [-o OUTDIR | --restart OUTDIR] [--set key=value]... [--threads N] [--quiet]

Simulates a scene of superelements and rigid bodies in absolute interface coordinates (see
formats/SCENE_FORMAT.md), with joints along a tree and closed loops cut into constraint equations:
  analysis.type: static   load stepping in pseudo-time, Newton with the full tangent, step cutting
  analysis.type: dynamic  analysis.integrator: generalized_alpha (numerical damping rho_inf) or
                          midpoint (momentum-conserving, no damping); analysis.step: a fixed step
                          (cut where Newton fails, with a warning) or auto (error-controlled by
                          analysis.step_tolerance; the steps are listed in results.h5 /steps)
  analysis.type: modes    linearized eigenfrequencies about the initial or the static state
  outputs                 probes at nodes (position, rotation, velocity, acceleration, joint,
                          reaction, effort of a prescribed joint) and at any point of a body
                          (position, velocity, acceleration, deformation, stress); stresses
                          (largest von Mises per body, stress_exclude near couplings); a ParaView
                          animation

options:
  -o, --output OUTDIR   output folder (default: out/<scene name>): results.h5, probes.csv and the
                        animation, written at the start, every outputs.flush_every seconds
                        (default 10) and at the end (a killed run keeps what was last written),
                        with checkpoint.h5, the state reached
  --restart OUTDIR      continue the dynamic run whose results are in OUTDIR from its
                        checkpoint (stopped by a signal, killed, or finished: then with a later
                        --set analysis.end_time=...), into the same files: the results equal the
                        uninterrupted run's to the bit
  --set key=value       override a scene key, e.g. --set analysis.step=5e-4
                        --set analysis.end_time=0.5 (repeatable)
  --threads N           threads for the bodies' forces and matrices in dynamic analysis
                        (default: the processors available; the results are the same bits
                        for any N)
  -q, --quiet           no progress lines
  -h, --help            this text

exit codes: 0 success, 2 bad input (one line names the file, line and key), 3 numerical failure
(the results up to the failure are kept in OUTDIR), 130 / 143 stopped by SIGINT (Ctrl-C) /
SIGTERM: the step under way is finished and the results up to it are written to OUTDIR (a
second signal ends the run at once, writing nothing); continue it with --restart OUTDIR.
)";

// The command line: what to solve, where to write, how.
struct Arguments {
  std::string scene_path, output, restart;
  std::vector<std::string> overrides;
  bool quiet = false;
  int threads = femb::DefaultThreads();
};

// The command line parsed, or nullopt with the exit code in *exit_code when the program ends here
// (--help: 0; a bad option: 2, after one line).
std::optional<Arguments> ParseArguments(int argc, char** argv, int* exit_code) {
  Arguments args;
  femb::CommandLine cli("femb-solve", kUsage, "scene file");
  cli.Value({"-o", "--output"}, [&](const std::string& v) { args.output = v; });
  cli.Value({"--set"}, [&](const std::string& v) { args.overrides.push_back(v); });
  cli.Switch({"-q", "--quiet"}, [&] { args.quiet = true; });
  cli.Value({"--restart"}, [&](const std::string& v) { args.restart = v; });
  std::string threads_text;
  cli.Value({"--threads"}, [&](const std::string& v) { threads_text = v; });
  if (!cli.Parse(argc, argv)) {
    *exit_code = cli.exit_code();
    return std::nullopt;
  }
  args.scene_path = cli.input();
  if (!threads_text.empty()) {
    char* end = nullptr;
    const long t = std::strtol(threads_text.c_str(), &end, 10);
    if (*end != '\0' || t < 1 || t > 1024) {
      std::fprintf(stderr, "femb-solve: --threads %s: expected a whole number from 1 to 1024\n", threads_text.c_str());
      *exit_code = 2;
      return std::nullopt;
    }
    args.threads = int(t);
  }
  return args;
}

// One run of femb-solve: the scene, the results written during the run, and the counts that the
// progress lines and the checkpoint carry. Run() reads what the run starts from (a checkpoint to
// continue, another run's state) and checks it before anything is written, then runs the
// analysis and writes the results, and returns the exit code. Bad input throws InputError.
class SolveRun {
 public:
  SolveRun(Arguments args, std::chrono::steady_clock::time_point wall)
      : args_(std::move(args)),
        wall_(wall),
        spec_(femb::ReadSceneFile(args_.scene_path, args_.overrides)),
        scene_(femb::BuildScene(spec_)) {}

  int Run() {
    ReadRestart();
    ReadInitialState();
    recorder_.emplace(scene_, args_.output);
    signature_ = femb::ModelSignature(scene_);
    if (resume_) ResumeRecorder();
    read_seconds_ = Seconds(wall_);  // scene, superelement files, model
    if (!args_.quiet) PrintSummary();
    if (spec_.analysis.type == femb::AnalysisType::kModes) return RunModes();
    if (spec_.analysis.type == femb::AnalysisType::kStatic) {
      RunStatic();
    } else {
      RunDynamic();
    }
    return Finish();
  }

 private:
  bool is_static() const { return spec_.analysis.type == femb::AnalysisType::kStatic; }
  femb::ResultsRecorder& recorder() { return *recorder_; }

  // --restart: what the stopped run carries into its next step, read and checked.
  void ReadRestart() {
    const std::string& restart = args_.restart;
    if (!restart.empty()) {
      if (!args_.output.empty() && std::filesystem::path(args_.output) != std::filesystem::path(restart)) {
        throw femb::InputError("--restart " + restart + " continues the run in that folder; leave out -o " +
                               args_.output);
      }
      args_.output = restart;
    }
    if (args_.output.empty()) args_.output = "out/" + spec_.name;
    if (restart.empty()) return;
    const std::string checkpoint = (std::filesystem::path(restart) / "checkpoint.h5").string();
    if (spec_.analysis.type != femb::AnalysisType::kDynamic) {
      throw femb::InputError("--restart " + restart +
                             ": continues dynamic analyses only (start one from a static run's "
                             "state with initial_state)");
    }
    resume_.emplace();
    if (!femb::ReadResume(restart, scene_, *resume_)) {
      throw femb::InputError(checkpoint +
                             ": holds no dynamic run to continue (a static run's state, or one written "
                             "before the first step: start anew, or from it with initial_state)");
    }
    if (!(spec_.analysis.end_time > resume_->state.t + 1e-12 * std::abs(spec_.analysis.end_time))) {
      char buffer[300];
      std::snprintf(buffer, sizeof buffer,
                    ": the run reached t = %.9g; analysis.end_time %.9g is not later (--set analysis.end_time=... "
                    "extends it)",
                    resume_->state.t, spec_.analysis.end_time);
      throw femb::InputError(checkpoint + buffer);
    }
  }

  // initial_state: the state another run reached, read and checked against this model (a
  // restarted run began from it already).
  void ReadInitialState() {
    if (spec_.initial_state.from.empty() || resume_) return;
    const femb::SceneSpec::InitialStateSpec& is = spec_.initial_state;
    if (spec_.analysis.type == femb::AnalysisType::kStatic) {
      throw femb::InputError(is.where +
                             ": initial_state: a static analysis starts from the model's placement (give it "
                             "to a dynamic or modes analysis)");
    }
    if (!spec_.initial_velocities.empty() || !spec_.initial_joint_rates.empty()) {
      throw femb::InputError(is.where + ": initial_state: the velocities are the state's; leave out initial_velocity");
    }
    std::filesystem::path dir(is.from);
    if (dir.is_relative()) dir = std::filesystem::path(spec_.file).parent_path() / dir;
    femb::AnalysisType kind = femb::AnalysisType::kStatic;
    from_ = femb::ReadCheckpoint(dir.string(), scene_, &kind);
    t0_ = is.time ? *is.time : kind == femb::AnalysisType::kDynamic ? from_->t : 0.0;
    if (spec_.analysis.type == femb::AnalysisType::kDynamic && !(spec_.analysis.end_time > t0_)) {
      char buffer[200];
      std::snprintf(buffer, sizeof buffer, ": analysis.end_time %.6g is not after the initial state's time %.6g",
                    spec_.analysis.end_time, t0_);
      throw femb::InputError(is.where + buffer);
    }
    if (!args_.quiet) {
      std::printf("femb-solve: initial state: the %s state of %s at t = %.6g, started at t = %.6g\n", femb::Name(kind),
                  dir.string().c_str(), from_->t, t0_);
    }
  }

  // The results and this program's counts of the run that --restart continues.
  void ResumeRecorder() {
    const femb::h5::Reader checkpoint((std::filesystem::path(args_.restart) / "checkpoint.h5").string());
    recorder().Resume(checkpoint);
    recorder().ResumedAt(resume_->state.t);
    const Eigen::VectorXd run = checkpoint.Vector("/run/counts");
    if (run.size() != 2) throw femb::InputError(checkpoint.path() + ": /run/counts must hold 2 values");
    step_count_ = long(run[0]), total_iterations_ = long(run[1]);
    if (!args_.quiet) {
      std::printf("femb-solve: restart: %s at t = %.6g (%ld steps, %ld output steps), to t = %.6g\n",
                  args_.restart.c_str(), resume_->state.t, step_count_, recorder().steps(), spec_.analysis.end_time);
    }
  }

  // The model's size, which inertia and stiffening the flexible bodies use, and the notes (one
  // per file, not per body) that say why when a body does without either.
  void PrintSummary() const {
    const int threads = args_.threads;
    std::printf("femb-solve: %s: %zu bodies, %d nodes, %d unknowns, %s analysis%s\n", args_.scene_path.c_str(),
                scene_.model.bodies.size(), scene_.model.n_nodes(), scene_.model.dofs().n_dofs(),
                femb::Name(spec_.analysis.type),
                spec_.analysis.type == femb::AnalysisType::kDynamic
                    ? (", " + std::to_string(threads) + (threads == 1 ? " thread" : " threads")).c_str()
                    : "");
    int flexible = 0, exact = 0, stiffened = 0;
    for (const femb::SuperelementBody& body : scene_.model.bodies) {
      if (body.n_coordinates() <= 6) continue;
      ++flexible;
      exact += body.has_exact_inertia();
      stiffened += body.options().geometric_stiffening && body.has_inertia_stiffening();
    }
    if (flexible > 0) {
      std::printf(
          "femb-solve: %d flexible bodies: %d with the exact inertia, %d with the corotational one; %d "
          "with geometric stiffening, %d linear inside\n",
          flexible, exact, flexible - exact, stiffened, flexible - stiffened);
    }
    std::set<std::string> said;
    for (const std::string& note : scene_.notes) {
      const std::string file = note.substr(note.find(": ") + 2);
      if (said.insert(file).second) std::printf("femb-solve: note: %s\n", note.c_str());
    }
  }

  // What a restart continues from, at an output step or the last step: the run's state and what
  // it carries into its next step, with the results' mark and this program's counts there.
  void Take(const femb::DynamicStepReport& report) {
    if (!saved_) saved_.emplace();
    (*report.capture)(*saved_);
    mark_ = recorder().TakeMark();
    saved_steps_ = step_count_, saved_iterations_ = total_iterations_;
  }
  void WriteCheckpoint(const femb::DynamicState& state) {
    const femb::AnalysisType kind = is_static() ? femb::AnalysisType::kStatic : femb::AnalysisType::kDynamic;
    if (!saved_) return femb::WriteCheckpoint(args_.output, scene_, signature_, state, kind);
    femb::WriteCheckpoint(args_.output, scene_, signature_, saved_->state, kind, &*saved_, [&](femb::h5::Writer& w) {
      recorder().WriteMark(w, mark_);
      w.CreateGroup("/run");
      w.Vector("/run/counts", Eigen::Vector2d(double(saved_steps_), double(saved_iterations_)));
    });
  }
  // Results on disk during the run (when due, or now with `force`): results.h5's status says how
  // far it got; the checkpoint follows the results it refers to.
  void Flush(const femb::DynamicState& state, bool force, const femb::DynamicStepReport* report = nullptr) {
    if (!force && !recorder().FlushDue()) return;
    char running[160];
    std::snprintf(running, sizeof running, "running: %s %.6g of %.6g (written during the run)",
                  is_static() ? "load factor" : "t =", state.t, spec_.analysis.end_time);
    if (report) Take(*report);
    recorder().Flush(running);
    WriteCheckpoint(state);
  }
  // A static state as a checkpoint's: the configuration at load factor t, at rest.
  static femb::DynamicState AtRest(const femb::SystemState& config, double t) {
    femb::DynamicState s;
    s.config = config;
    s.t = t;
    return s;
  }
  // A progress line at most once a second (or now with `force`), with the largest violation of
  // the closed loops' equations so far (a length).
  void Progress(double t, bool force) {
    if (args_.quiet) return;
    if (!force && Seconds(wall_) - last_print_ < 1.0) return;
    last_print_ = Seconds(wall_);
    char loops[64] = "";
    if (scene_.model.has_constraints())
      std::snprintf(loops, sizeof loops, " loop gap %.2g", recorder().max_loop_violation());
    if (spec_.analysis.adaptive_step) {
      std::printf("femb-solve: t = %-10.6g steps %-7ld rejected %-5ld Newton iterations %-8ld wall %.2f s%s\n", t,
                  step_count_, rejected_, total_iterations_, Seconds(wall_), loops);
    } else {
      std::printf("femb-solve: t = %-10.6g steps %-7ld Newton iterations %-8ld wall %.2f s%s\n", t, step_count_,
                  total_iterations_, Seconds(wall_), loops);
    }
    std::fflush(stdout);
  }

  // analysis.type modes: the linearized modes about the initial (or static) state, their shapes
  // as output steps, the frequencies in modes.csv. The exit code.
  int RunModes() {
    femb::SystemState state = from_ ? from_->config : femb::InitialState(scene_.model);
    double load_time = t0_;
    if (spec_.analysis.modes_about_static && !from_) {
      const femb::StaticResult r = femb::SolveStatic(scene_.model, state, StaticOptionsOf(spec_.analysis));
      if (!r.ok) {
        recorder().Finish(r.message);
        std::fprintf(stderr, "femb-solve: %s: numerical failure in the static state for the modes: %s\n",
                     args_.scene_path.c_str(), r.message.c_str());
        return 3;
      }
      load_time = spec_.analysis.end_time;
    }
    recorder().Record(load_time, state, Eigen::VectorXd(), 0.0, 0.0, 0.0);
    const femb::ModalResult modes = femb::LinearizedModes(scene_.model, state, load_time, spec_.analysis.mode_count);
    if (modes.ok) RecordModeShapes(scene_, state, modes, load_time, recorder());
    recorder().Finish(modes.ok ? "completed" : modes.message);
    if (!modes.ok) {
      std::fprintf(stderr, "femb-solve: %s: numerical failure: %s\n", args_.scene_path.c_str(), modes.message.c_str());
      return 3;
    }
    const std::string path = args_.output + "/modes.csv";
    {
      std::ofstream out(path + ".tmp");
      out << "mode,frequency_hz\n";
      for (int k = 0; k < modes.frequencies_hz.size(); ++k) {
        out << k + 1 << "," << modes.frequencies_hz[k] << "\n";
        if (!args_.quiet) std::printf("femb-solve: mode %3d  %14.6g Hz\n", k + 1, modes.frequencies_hz[k]);
      }
    }
    std::rename((path + ".tmp").c_str(), path.c_str());
    if (!args_.quiet) std::printf("femb-solve: frequencies in %s\n", path.c_str());
    return 0;
  }

  // The joints' reactions at a static state, when the scene asks for them (an assembly per
  // output step).
  std::vector<Eigen::Matrix<double, 6, 1>> StaticReactions(double lambda, const femb::SystemState& st) const {
    std::vector<Eigen::Matrix<double, 6, 1>> out;
    if (!spec_.reactions) return out;
    femb::SystemState copy = st;
    const femb::SystemForces f = femb::AssembleStatic(scene_.model, scene_.model.dofs(), copy, lambda, false);
    return femb::JointReactions(scene_.model, scene_.model.dofs(), copy, f.node_forces);
  }

  // analysis.type static: load stepping, recording every output_every-th step.
  void RunStatic() {
    femb::SystemState state = femb::InitialState(scene_.model);
    const auto reactions0 = StaticReactions(0.0, state);
    recorder().Record(0.0, state, Eigen::VectorXd(), 0.0, 0.0, 0.0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                      spec_.reactions ? &reactions0 : nullptr);
    Flush(AtRest(state, 0.0), true);
    femb::StaticOptions static_options = StaticOptionsOf(spec_.analysis);
    static_options.stop = &femb::StopRequest();
    const femb::StaticResult r = femb::SolveStatic(
        scene_.model, state, static_options, [&](const femb::StaticStepReport& s, const femb::SystemState& st) {
          ++step_count_;
          total_iterations_ += s.iterations;
          if (step_count_ % spec_.analysis.output_every == 0) {
            const auto reactions = StaticReactions(s.lambda, st);
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
    for (const std::string& w : r.warnings) std::printf("femb-solve: warning: %s\n", w.c_str());
  }

  // The dynamic analysis' options from the scene's analysis and the command line.
  femb::DynamicOptions DynamicOptionsOf() {
    const femb::SceneAnalysisSpec& a = spec_.analysis;
    femb::DynamicOptions options;
    options.step = a.step;
    options.end_time = a.end_time;
    options.rho_inf = a.rho_inf;
    options.integrator = a.integrator;
    options.tolerance = a.tolerance;
    options.max_iterations = a.max_iterations;
    options.jacobian_reuse = a.jacobian_reuse;  // unset: the integrator's (femb::JacobianReuseOf)
    options.full_inertia_tangent = a.gyroscopic_tangent;
    if (a.body_matrices_every > 0) options.body_matrices_every = a.body_matrices_every;
    options.body_matrices_kept = a.body_matrices_kept;
    options.threads = args_.threads;
    options.stop = &femb::StopRequest();
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
  femb::DynamicState InitialDynamicState() {
    if (resume_) return resume_->state;
    femb::DynamicState state =
        from_ ? femb::InitialDynamicState(scene_.model, from_->config,
                                          from_->W.size() ? from_->W : scene_.initial_velocity, t0_)
              : femb::InitialDynamicState(scene_.model, femb::InitialState(scene_.model), scene_.initial_velocity);
    const femb::DynamicStepReport r0 = femb::Measure(scene_.model, state);
    const auto reactions0 =
        spec_.reactions ? femb::DynamicReactions(scene_.model, state) : std::vector<Eigen::Matrix<double, 6, 1>>();
    recorder().Record(state.t, state.config, state.W, r0.kinetic_energy, r0.elastic_energy, 0.0, r0.linear_momentum,
                      r0.angular_momentum, spec_.reactions ? &reactions0 : nullptr, &state.Wdot);
    recorder().RecordStepSize(0.0);
    Flush(state, true);
    return state;
  }

  // analysis.type dynamic: time stepping, recording at output_step's times (adaptive steps land
  // on them) or every output_every-th step.
  void RunDynamic() {
    femb::DynamicState state = InitialDynamicState();
    const femb::DynamicOptions options = DynamicOptionsOf();
    femb::DynamicState output_state;
    const femb::DynamicResult r = femb::SolveDynamic(
        scene_.model, state, options, [&](const femb::DynamicStepReport& s, const femb::DynamicState& st) {
          ++step_count_;
          total_iterations_ += s.iterations;
          rejected_ = s.rejected;
          recorder().RecordStep(s.t, s.h);
          if (spec_.analysis.output_step > 0 ? s.output : step_count_ % spec_.analysis.output_every == 0) {
            // Reactions from the output state's consistent accelerations and multipliers, not
            // from the integrator's own (WithConsistentAccelerations).
            const femb::DynamicState& out =
                spec_.reactions ? (output_state = femb::WithConsistentAccelerations(scene_.model, st)) : st;
            const auto reactions = spec_.reactions ? femb::DynamicReactions(scene_.model, out)
                                                   : std::vector<Eigen::Matrix<double, 6, 1>>();
            recorder().Record(s.t, out.config, out.W, s.kinetic_energy, s.elastic_energy, s.external_work,
                              s.linear_momentum, s.angular_momentum, spec_.reactions ? &reactions : nullptr, &out.Wdot);
            recorder().RecordStepSize(s.h);
            Flush(st, false, &s);
          }
          if (s.last) Take(s);
          Progress(s.t, false);
        });
    ok_ = r.ok;
    if (!ok_) status_ = r.message;
    stopped_ = r.stopped;
    stopped_at_ = state.t;
    final_state_ = state;
    for (const std::string& w : r.warnings) std::printf("femb-solve: warning: %s\n", w.c_str());
    if (!args_.quiet) PrintDynamicCounts(r, options);
    recorder().StepCounts(r.steps, r.rejected_by_error, r.newton_cuts);
  }

  // The factorizations, the bodies' matrices and, with error-controlled steps, the steps'
  // statistics.
  void PrintDynamicCounts(const femb::DynamicResult& r, const femb::DynamicOptions& options) const {
    const std::string analysed = r.pattern_analyses == 1 ? "once" : std::to_string(r.pattern_analyses) + " times";
    std::printf(
        "femb-solve: %ld factorizations of the iteration matrix; its sparsity pattern analysed %s; pivots "
        "chosen in %ld, reused in %ld\n",
        r.factorizations, analysed.c_str(), r.pivoted, r.factorizations - r.pivoted);
    if (r.body_matrices_turned > 0) {
      const bool all = options.body_matrices_kept == femb::BodyMatricesKept::kAll;
      std::printf(
          "femb-solve: bodies' %smatrices computed %ld times, turned with their floating frames %ld times "
          "(analysis.body_matrices_every %d, body_matrices_kept %s)\n",
          all ? "" : "inertia ", r.body_matrices_computed, r.body_matrices_turned, options.body_matrices_every,
          all ? "all" : "inertia");
    }
    if (!spec_.analysis.adaptive_step) return;
    std::printf("femb-solve: %ld steps rejected (%ld by the error test, %ld by Newton)\n",
                r.rejected_by_error + r.newton_cuts, r.rejected_by_error, r.newton_cuts);
    if (r.steps > 0) {
      std::printf(
          "femb-solve: steps: smallest %.3g s (ending at t = %.6g), largest %.3g s, mean %.3g s; every step "
          "in results.h5 /steps\n",
          r.smallest_step, r.smallest_step_time, r.largest_step, spec_.analysis.end_time / double(r.steps));
    }
  }

  // The results' status and the checkpoint written, the stresses summarized; the exit code.
  int Finish() {
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
    WriteCheckpoint(final_state_);
    if (!stopped_) Progress(spec_.analysis.end_time, true);
    if (!args_.quiet) {
      for (const std::string& line : recorder().StressSummary()) std::printf("femb-solve: %s\n", line.c_str());
    }
    if (stopped_) {
      std::fprintf(stderr, "femb-solve: %s: %s; results up to it are in %s\n", args_.scene_path.c_str(),
                   status_.c_str(), args_.output.c_str());
      return 128 + stopped_;
    }
    if (!ok_) {
      std::fprintf(stderr, "femb-solve: %s: numerical failure: %s; results up to it are in %s\n",
                   args_.scene_path.c_str(), status_.c_str(), args_.output.c_str());
      return 3;
    }
    if (args_.quiet) return 0;
    if (recorder().flushes() > 0) {
      const std::string times = recorder().flushes() == 1 ? "once" : std::to_string(recorder().flushes()) + " times";
      std::printf("femb-solve: results written %s during the run (outputs.flush_every %g s), %.3f s in all\n",
                  times.c_str(), spec_.flush_every, recorder().flush_seconds());
    }
    // The phases: reading (scene, superelement files, model), the analysis with its per-step
    // recording, writing results.h5 and the animation.
    const double end = Seconds(wall_);
    std::printf(
        "femb-solve: done in %.2f s (reading %.3f s, solving %.3f s, writing %.3f s): %ld steps, %.2f "
        "Newton iterations per step; results in %s, %s\n",
        end, read_seconds_, solve_end - read_seconds_, end - solve_end, step_count_,
        step_count_ ? double(total_iterations_) / step_count_ : 0.0, recorder().h5_path().c_str(),
        recorder().csv_path().c_str());
    return 0;
  }

  Arguments args_;
  std::chrono::steady_clock::time_point wall_;
  const femb::SceneSpec spec_;
  const femb::Scene scene_;
  std::optional<femb::DynamicResume> resume_;  ///< --restart
  std::optional<femb::DynamicState> from_;     ///< initial_state
  double t0_ = 0.0;                            ///< the time the run starts at
  std::optional<femb::ResultsRecorder> recorder_;
  std::string signature_;
  double read_seconds_ = 0.0;
  long step_count_ = 0, total_iterations_ = 0;
  long rejected_ = 0;  ///< steps rejected so far (step: auto)
  double last_print_ = -1.0;
  std::string status_ = "completed";
  bool ok_ = true;
  int stopped_ = 0;                 ///< the signal that stopped the analysis, or 0
  double stopped_at_ = 0.0;         ///< the time (static: load factor) it stopped at
  femb::DynamicState final_state_;  ///< the state the analysis ended in (static: at rest)
  // What a restart continues from (Take), with the results' mark and the counts there.
  std::optional<femb::DynamicResume> saved_;
  femb::ResultsRecorder::Mark mark_;
  long saved_steps_ = 0, saved_iterations_ = 0;
};

}  // namespace

int main(int argc, char** argv) {
  int exit_code = 0;
  std::optional<Arguments> args = ParseArguments(argc, argv, &exit_code);
  if (!args) return exit_code;
  femb::InstallStopHandlers();
  try {
    const auto wall = std::chrono::steady_clock::now();
    SolveRun run(std::move(*args), wall);
    return run.Run();
  } catch (const femb::InputError& e) {
    std::fprintf(stderr, "femb-solve: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "femb-solve: internal error: %s\n", e.what());
    return 1;
  }
}
