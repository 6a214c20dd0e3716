// femb-solve: simulate a scene of superelements (static or dynamic).
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include "formats/command_line.h"
#include "formats/input_error.h"
#include "formats/scene_file.h"
#include "solver/parallel.h"
#include "solver/run/solve_run.h"
#include "solver/stop_request.h"

namespace {

constexpr const char* kUsage =
    R"(usage: femb-solve SCENE.yaml [-o OUTDIR | --restart OUTDIR] [--set key=value]... [--threads N] [--quiet]

Simulates a scene of superelements and rigid bodies in absolute interface coordinates (see
formats/SCENE_FORMAT.md), with joints along a tree and closed loops cut into constraint equations:
  analysis.type: static   load stepping in pseudo-time, Newton with the full tangent, step cutting
  analysis.type: dynamic  analysis.integrator: generalized_alpha (numerical damping rho_inf),
                          midpoint (momentum-conserving, no damping) or radau (fifth order,
                          L-stable); analysis.step: a fixed step
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
  --threads N           threads for the bodies' forces and matrices in static and dynamic analysis
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

}  // namespace

int main(int argc, char** argv) {
  int exit_code = 0;
  std::optional<Arguments> args = ParseArguments(argc, argv, &exit_code);
  if (!args) return exit_code;
  femb::InstallStopHandlers();
  try {
    const auto print = [](const std::string& line) {
      std::printf("femb-solve: %s\n", line.c_str());
      std::fflush(stdout);
    };
    femb::SolveRunOptions options;
    options.output = args->output;
    options.restart = args->restart;
    options.threads = args->threads;
    if (!args->quiet) options.progress = print;
    options.warning = print;
    options.stop = &femb::StopRequest();
    femb::SolveRun run(femb::ReadSceneFile(args->scene_path, args->overrides), std::move(options));
    const int code = run.Run();
    if (code != 0) std::fprintf(stderr, "femb-solve: %s\n", run.error().c_str());
    return code;
  } catch (const femb::InputError& e) {
    std::fprintf(stderr, "femb-solve: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "femb-solve: internal error: %s\n", e.what());
    return 1;
  }
}
