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

}  // namespace

int main(int argc, char** argv) {
  std::string output;
  std::vector<std::string> overrides;
  bool quiet = false;
  femb::CommandLine cli("femb-solve", kUsage, "scene file");
  cli.Value({"-o", "--output"}, [&](const std::string& v) { output = v; });
  cli.Value({"--set"}, [&](const std::string& v) { overrides.push_back(v); });
  cli.Switch({"-q", "--quiet"}, [&] { quiet = true; });
  std::string restart;
  cli.Value({"--restart"}, [&](const std::string& v) { restart = v; });
  int threads = femb::DefaultThreads();
  std::string threads_text;
  cli.Value({"--threads"}, [&](const std::string& v) { threads_text = v; });
  if (!cli.Parse(argc, argv)) return cli.exit_code();
  const std::string scene_path = cli.input();
  if (!threads_text.empty()) {
    char* end = nullptr;
    const long t = std::strtol(threads_text.c_str(), &end, 10);
    if (*end != '\0' || t < 1 || t > 1024) {
      std::fprintf(stderr, "femb-solve: --threads %s: expected a whole number from 1 to 1024\n", threads_text.c_str());
      return 2;
    }
    threads = int(t);
  }
  femb::InstallStopHandlers();
  try {
    const auto wall = std::chrono::steady_clock::now();
    const femb::SceneSpec spec = femb::ReadSceneFile(scene_path, overrides);
    const femb::Scene scene = femb::BuildScene(spec);
    if (!restart.empty()) {
      if (!output.empty() && std::filesystem::path(output) != std::filesystem::path(restart)) {
        throw femb::InputError("--restart " + restart + " continues the run in that folder; leave out -o " + output);
      }
      output = restart;
    }
    if (output.empty()) output = "out/" + spec.name;
    // --restart: what the stopped run carries into its next step, read and checked before
    // anything is written.
    std::optional<femb::DynamicResume> resume;
    if (!restart.empty()) {
      const std::string checkpoint = (std::filesystem::path(restart) / "checkpoint.h5").string();
      if (spec.analysis.type != femb::AnalysisType::kDynamic) {
        throw femb::InputError("--restart " + restart +
                               ": continues dynamic analyses only (start one from a static run's "
                               "state with initial_state)");
      }
      resume.emplace();
      if (!femb::ReadResume(restart, scene, *resume)) {
        throw femb::InputError(checkpoint +
                               ": holds no dynamic run to continue (a static run's state, or one written "
                               "before the first step: start anew, or from it with initial_state)");
      }
      if (!(spec.analysis.end_time > resume->state.t + 1e-12 * std::abs(spec.analysis.end_time))) {
        char buffer[300];
        std::snprintf(buffer, sizeof buffer,
                      ": the run reached t = %.9g; analysis.end_time %.9g is not later (--set analysis.end_time=... "
                      "extends it)",
                      resume->state.t, spec.analysis.end_time);
        throw femb::InputError(checkpoint + buffer);
      }
    }
    // initial_state: the state another run reached, read (and checked against this model)
    // before anything is written.
    std::optional<femb::DynamicState> from;
    double t0 = 0.0;
    if (!spec.initial_state.from.empty() && !resume) {  // a restarted run began from it already
      const femb::SceneSpec::InitialStateSpec& is = spec.initial_state;
      if (spec.analysis.type == femb::AnalysisType::kStatic) {
        throw femb::InputError(is.where +
                               ": initial_state: a static analysis starts from the model's placement (give it "
                               "to a dynamic or modes analysis)");
      }
      if (!spec.initial_velocities.empty() || !spec.initial_joint_rates.empty()) {
        throw femb::InputError(is.where +
                               ": initial_state: the velocities are the state's; leave out initial_velocity");
      }
      std::filesystem::path dir(is.from);
      if (dir.is_relative()) dir = std::filesystem::path(spec.file).parent_path() / dir;
      std::string kind;
      from = femb::ReadCheckpoint(dir.string(), scene, &kind);
      t0 = is.time ? *is.time : kind == "dynamic" ? from->t : 0.0;
      if (spec.analysis.type == femb::AnalysisType::kDynamic && !(spec.analysis.end_time > t0)) {
        char buffer[200];
        std::snprintf(buffer, sizeof buffer, ": analysis.end_time %.6g is not after the initial state's time %.6g",
                      spec.analysis.end_time, t0);
        throw femb::InputError(is.where + buffer);
      }
      if (!quiet) {
        std::printf("femb-solve: initial state: the %s state of %s at t = %.6g, started at t = %.6g\n", kind.c_str(),
                    dir.string().c_str(), from->t, t0);
      }
    }
    femb::ResultsRecorder recorder(scene, output);
    const std::string signature = femb::ModelSignature(scene);
    long step_count = 0;
    long total_iterations = 0;
    if (resume) {
      const femb::h5::Reader checkpoint((std::filesystem::path(restart) / "checkpoint.h5").string());
      recorder.Resume(checkpoint);
      recorder.ResumedAt(resume->state.t);
      const Eigen::VectorXd run = checkpoint.Vector("/run/counts");
      if (run.size() != 2) throw femb::InputError(checkpoint.path() + ": /run/counts must hold 2 values");
      step_count = long(run[0]), total_iterations = long(run[1]);
      if (!quiet) {
        std::printf("femb-solve: restart: %s at t = %.6g (%ld steps, %ld output steps), to t = %.6g\n", restart.c_str(),
                    resume->state.t, step_count, recorder.steps(), spec.analysis.end_time);
      }
    }
    const femb::DofMap& dofs = scene.model.dofs();
    const double read_seconds = Seconds(wall);  // scene, superelement files, model
    if (!quiet) {
      std::printf("femb-solve: %s: %zu bodies, %d nodes, %d unknowns, %s analysis%s\n", scene_path.c_str(),
                  scene.model.bodies.size(), scene.model.n_nodes(), dofs.n_dofs(), femb::Name(spec.analysis.type),
                  spec.analysis.type == femb::AnalysisType::kDynamic
                      ? (", " + std::to_string(threads) + (threads == 1 ? " thread" : " threads")).c_str()
                      : "");
      // Which inertia and stiffening the flexible bodies use (the notes below say why when a
      // body does without the exact inertia or the stiffening).
      int flexible = 0, exact = 0, stiffened = 0;
      for (const femb::SuperelementBody& body : scene.model.bodies) {
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
      // One note per file, not per body.
      std::set<std::string> said;
      for (const std::string& note : scene.notes) {
        const std::string file = note.substr(note.find(": ") + 2);
        if (said.insert(file).second) std::printf("femb-solve: note: %s\n", note.c_str());
      }
    }
    std::string status = "completed";
    bool ok = true;
    int stopped = 0;          // the signal that stopped the analysis, or 0
    double stopped_at = 0.0;  // the time (static: load factor) it stopped at
    long rejected = 0;        // steps rejected so far (step: auto)
    // Results on disk during the run: results.h5's status says how far it got.
    const bool is_static = spec.analysis.type == femb::AnalysisType::kStatic;
    const char* kind = is_static ? "static" : "dynamic";
    // What a restart continues from: the run's state and what it carries into its next step
    // (captured at each write during the run and at the last step), with the results' mark and
    // this program's counts at that state.
    std::optional<femb::DynamicResume> saved;
    femb::DynamicState final_state;  // the state the analysis ended in (static: at rest)
    femb::ResultsRecorder::Mark mark;
    long saved_steps = 0, saved_iterations = 0;
    const auto take = [&](const femb::DynamicStepReport& report) {
      if (!saved) saved.emplace();
      (*report.capture)(*saved);
      mark = recorder.TakeMark();
      saved_steps = step_count, saved_iterations = total_iterations;
    };
    const auto write_checkpoint = [&](const femb::DynamicState& state) {
      if (!saved) return femb::WriteCheckpoint(output, scene, signature, state, kind);
      femb::WriteCheckpoint(output, scene, signature, saved->state, kind, &*saved, [&](femb::h5::Writer& w) {
        recorder.WriteMark(w, mark);
        w.CreateGroup("/run");
        w.Vector("/run/counts", Eigen::Vector2d(double(saved_steps), double(saved_iterations)));
      });
    };
    auto flush = [&](const femb::DynamicState& state, bool force, const femb::DynamicStepReport* report = nullptr) {
      if (!force && !recorder.FlushDue()) return;
      char running[160];
      std::snprintf(running, sizeof running, "running: %s %.6g of %.6g (written during the run)",
                    is_static ? "load factor" : "t =", state.t, spec.analysis.end_time);
      if (report) take(*report);
      recorder.Flush(running);
      write_checkpoint(state);
    };
    // A static state as a checkpoint's: the configuration at load factor t, at rest.
    auto at_rest = [](const femb::SystemState& config, double t) {
      femb::DynamicState s;
      s.config = config;
      s.t = t;
      return s;
    };
    double last_print = -1.0;
    auto progress = [&](double t, bool force) {
      if (quiet) return;
      if (!force && Seconds(wall) - last_print < 1.0) return;
      last_print = Seconds(wall);
      // Closed loops: the largest violation of their equations so far (a length).
      char loops[64] = "";
      if (scene.model.has_constraints())
        std::snprintf(loops, sizeof loops, " loop gap %.2g", recorder.max_loop_violation());
      if (spec.analysis.adaptive_step) {
        std::printf("femb-solve: t = %-10.6g steps %-7ld rejected %-5ld Newton iterations %-8ld wall %.2f s%s\n", t,
                    step_count, rejected, total_iterations, Seconds(wall), loops);
      } else {
        std::printf("femb-solve: t = %-10.6g steps %-7ld Newton iterations %-8ld wall %.2f s%s\n", t, step_count,
                    total_iterations, Seconds(wall), loops);
      }
      std::fflush(stdout);
    };
    if (spec.analysis.type == femb::AnalysisType::kModes) {
      femb::SystemState state = from ? from->config : femb::InitialState(scene.model);
      double load_time = t0;
      if (spec.analysis.modes_about_static && !from) {
        const femb::StaticResult r = femb::SolveStatic(scene.model, state, StaticOptionsOf(spec.analysis));
        if (!r.ok) {
          recorder.Finish(r.message);
          std::fprintf(stderr, "femb-solve: %s: numerical failure in the static state for the modes: %s\n",
                       scene_path.c_str(), r.message.c_str());
          return 3;
        }
        load_time = spec.analysis.end_time;
      }
      recorder.Record(load_time, state, Eigen::VectorXd(), 0.0, 0.0, 0.0);
      const femb::ModalResult modes = femb::LinearizedModes(scene.model, state, load_time, spec.analysis.mode_count);
      if (modes.ok) RecordModeShapes(scene, state, modes, load_time, recorder);
      recorder.Finish(modes.ok ? "completed" : modes.message);
      if (!modes.ok) {
        std::fprintf(stderr, "femb-solve: %s: numerical failure: %s\n", scene_path.c_str(), modes.message.c_str());
        return 3;
      }
      const std::string path = output + "/modes.csv";
      {
        std::ofstream out(path + ".tmp");
        out << "mode,frequency_hz\n";
        for (int k = 0; k < modes.frequencies_hz.size(); ++k) {
          out << k + 1 << "," << modes.frequencies_hz[k] << "\n";
          if (!quiet) std::printf("femb-solve: mode %3d  %14.6g Hz\n", k + 1, modes.frequencies_hz[k]);
        }
      }
      std::rename((path + ".tmp").c_str(), path.c_str());
      if (!quiet) std::printf("femb-solve: frequencies in %s\n", path.c_str());
      return 0;
    }
    if (spec.analysis.type == femb::AnalysisType::kStatic) {
      femb::SystemState state = femb::InitialState(scene.model);
      // Reactions only when the scene asks (an assembly per output step).
      auto static_reactions = [&](double lambda, const femb::SystemState& st) {
        std::vector<Eigen::Matrix<double, 6, 1>> out;
        if (!spec.reactions) return out;
        femb::SystemState copy = st;
        const femb::SystemForces f = femb::AssembleStatic(scene.model, dofs, copy, lambda, false);
        return femb::JointReactions(scene.model, dofs, copy, f.node_forces);
      };
      auto reactions0 = static_reactions(0.0, state);
      recorder.Record(0.0, state, Eigen::VectorXd(), 0.0, 0.0, 0.0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                      spec.reactions ? &reactions0 : nullptr);
      flush(at_rest(state, 0.0), true);
      femb::StaticOptions static_options = StaticOptionsOf(spec.analysis);
      static_options.stop = &femb::StopRequest();
      const femb::StaticResult r = femb::SolveStatic(
          scene.model, state, static_options, [&](const femb::StaticStepReport& s, const femb::SystemState& st) {
            ++step_count;
            total_iterations += s.iterations;
            if (step_count % spec.analysis.output_every == 0) {
              const auto reactions = static_reactions(s.lambda, st);
              recorder.Record(s.lambda, st, Eigen::VectorXd(), 0.0, s.elastic_energy, s.external_work,
                              Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), spec.reactions ? &reactions : nullptr);
              if (recorder.FlushDue()) flush(at_rest(st, s.lambda), true);
            }
            progress(s.lambda, false);
          });
      ok = r.ok;
      if (!ok) status = r.message;
      stopped = r.stopped;
      stopped_at = r.steps.empty() ? 0.0 : r.steps.back().lambda;
      final_state = at_rest(state, stopped_at);
      for (const std::string& w : r.warnings) std::printf("femb-solve: warning: %s\n", w.c_str());
    } else {
      femb::DynamicState state =
          resume ? resume->state
          : from ? femb::InitialDynamicState(scene.model, from->config,
                                             from->W.size() ? from->W : scene.initial_velocity, t0)
                 : femb::InitialDynamicState(scene.model, femb::InitialState(scene.model), scene.initial_velocity);
      if (!resume) {
        const femb::DynamicStepReport r0 = femb::Measure(scene.model, state);
        const auto reactions0 =
            spec.reactions ? femb::DynamicReactions(scene.model, state) : std::vector<Eigen::Matrix<double, 6, 1>>();
        recorder.Record(state.t, state.config, state.W, r0.kinetic_energy, r0.elastic_energy, 0.0, r0.linear_momentum,
                        r0.angular_momentum, spec.reactions ? &reactions0 : nullptr, &state.Wdot);
        recorder.RecordStepSize(0.0);
        flush(state, true);
      }
      femb::DynamicOptions options;
      options.step = spec.analysis.step;
      options.end_time = spec.analysis.end_time;
      options.rho_inf = spec.analysis.rho_inf;
      if (spec.analysis.integrator == femb::IntegratorType::kMidpoint) options.integrator = femb::Integrator::kMidpoint;
      options.tolerance = spec.analysis.tolerance;
      options.max_iterations = spec.analysis.max_iterations;
      switch (spec.analysis.jacobian_reuse) {
        case femb::JacobianReuseType::kDefault:
          break;  // the integrator's (femb::JacobianReuseOf)
        case femb::JacobianReuseType::kNone:
          options.jacobian_reuse = femb::JacobianReuse::kNone;
          break;
        case femb::JacobianReuseType::kStep:
          options.jacobian_reuse = femb::JacobianReuse::kStep;
          break;
        case femb::JacobianReuseType::kSteps:
          options.jacobian_reuse = femb::JacobianReuse::kSteps;
          break;
      }
      options.full_inertia_tangent = spec.analysis.gyroscopic_tangent;
      if (spec.analysis.body_matrices_every > 0) options.body_matrices_every = spec.analysis.body_matrices_every;
      options.body_matrices_kept = spec.analysis.body_matrices_kept == femb::BodyMatricesKeptType::kAll
                                       ? femb::BodyMatricesKept::kAll
                                       : femb::BodyMatricesKept::kInertia;
      options.threads = threads;
      options.stop = &femb::StopRequest();
      if (resume) options.resume = &*resume;
      options.adaptive = spec.analysis.adaptive_step;
      if (options.adaptive) options.step = 1e-4 * spec.analysis.end_time;  // the first step tried
      options.step_tolerance = spec.analysis.step_tolerance;
      options.min_step = spec.analysis.min_step;
      options.max_step = spec.analysis.max_step;
      options.output_step = spec.analysis.output_step;
      for (const auto& [name, f] : spec.functions) {
        for (double t : f.Breakpoints()) options.breakpoints.push_back(t);
      }
      femb::DynamicState output_state;
      const femb::DynamicResult r = femb::SolveDynamic(
          scene.model, state, options, [&](const femb::DynamicStepReport& s, const femb::DynamicState& st) {
            ++step_count;
            total_iterations += s.iterations;
            rejected = s.rejected;
            recorder.RecordStep(s.t, s.h);
            // output_step picks the output steps (adaptive steps land on its times); else every
            // output_every-th step.
            if (spec.analysis.output_step > 0 ? s.output : step_count % spec.analysis.output_every == 0) {
              // Reactions from the output state's consistent accelerations and multipliers, not
              // from the integrator's own (WithConsistentAccelerations).
              const femb::DynamicState& out =
                  spec.reactions ? (output_state = femb::WithConsistentAccelerations(scene.model, st)) : st;
              const auto reactions = spec.reactions ? femb::DynamicReactions(scene.model, out)
                                                    : std::vector<Eigen::Matrix<double, 6, 1>>();
              recorder.Record(s.t, out.config, out.W, s.kinetic_energy, s.elastic_energy, s.external_work,
                              s.linear_momentum, s.angular_momentum, spec.reactions ? &reactions : nullptr, &out.Wdot);
              recorder.RecordStepSize(s.h);
              flush(st, false, &s);
            }
            if (s.last) take(s);
            progress(s.t, false);
          });
      ok = r.ok;
      if (!ok) status = r.message;
      stopped = r.stopped;
      stopped_at = state.t;
      final_state = state;
      for (const std::string& w : r.warnings) std::printf("femb-solve: warning: %s\n", w.c_str());
      if (!quiet) {
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
      }
      if (!quiet && spec.analysis.adaptive_step) {
        std::printf("femb-solve: %ld steps rejected (%ld by the error test, %ld by Newton)\n",
                    r.rejected_by_error + r.newton_cuts, r.rejected_by_error, r.newton_cuts);
        if (r.steps > 0) {
          std::printf(
              "femb-solve: steps: smallest %.3g s (ending at t = %.6g), largest %.3g s, mean %.3g s; every step "
              "in results.h5 /steps\n",
              r.smallest_step, r.smallest_step_time, r.largest_step, spec.analysis.end_time / double(r.steps));
        }
      }
      recorder.StepCounts(r.steps, r.rejected_by_error, r.newton_cuts);
    }
    const double solve_end = Seconds(wall);
    const char* signal_name = stopped == SIGINT ? "SIGINT" : stopped == SIGTERM ? "SIGTERM" : "a signal";
    if (stopped) {
      char buffer[200];
      std::snprintf(buffer, sizeof buffer, "stopped by %s at %s %.6g of %.6g", signal_name,
                    spec.analysis.type == femb::AnalysisType::kStatic ? "load factor" : "t =", stopped_at,
                    spec.analysis.end_time);
      status = buffer;
    }
    recorder.Finish(status);
    // The checkpoint after the results it refers to (a kill between the two leaves the older one).
    write_checkpoint(final_state);
    if (!stopped) progress(spec.analysis.end_time, true);
    if (!quiet) {
      for (const std::string& line : recorder.StressSummary()) std::printf("femb-solve: %s\n", line.c_str());
    }
    if (stopped) {
      std::fprintf(stderr, "femb-solve: %s: %s; results up to it are in %s\n", scene_path.c_str(), status.c_str(),
                   output.c_str());
      return 128 + stopped;
    }
    if (!ok) {
      std::fprintf(stderr, "femb-solve: %s: numerical failure: %s; results up to it are in %s\n", scene_path.c_str(),
                   status.c_str(), output.c_str());
      return 3;
    }
    if (!quiet && recorder.flushes() > 0) {
      const std::string times = recorder.flushes() == 1 ? "once" : std::to_string(recorder.flushes()) + " times";
      std::printf("femb-solve: results written %s during the run (outputs.flush_every %g s), %.3f s in all\n",
                  times.c_str(), spec.flush_every, recorder.flush_seconds());
    }
    if (!quiet) {
      // The phases: reading (scene, superelement files, model), the analysis with its per-step
      // recording, writing results.h5 and the animation.
      const double end = Seconds(wall);
      std::printf(
          "femb-solve: done in %.2f s (reading %.3f s, solving %.3f s, writing %.3f s): %ld steps, %.2f "
          "Newton iterations per step; results in %s, %s\n",
          end, read_seconds, solve_end - read_seconds, end - solve_end, step_count,
          step_count ? double(total_iterations) / step_count : 0.0, recorder.h5_path().c_str(),
          recorder.csv_path().c_str());
    }
    return 0;
  } catch (const femb::InputError& e) {
    std::fprintf(stderr, "femb-solve: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "femb-solve: internal error: %s\n", e.what());
    return 1;
  }
}
