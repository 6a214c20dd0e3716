// Solver scaling: a chain of N flexible bodies (tube segments, 2 internal modes each) clamped
// at one end and falling under gravity; time per dynamic step and Newton iterations per step
// for N = 1, 10, 100, 1000, linear bodies and bodies with the geometric stiffening and exact
// inertia (reduction.geometric_stiffening: the cost ratio per body-step), on one
// thread and on all the processors (bodies in parallel: the speed-up, same bits).
// Prints what it measured on this run, with the heap allocations per body-step (malloc, which
// Eigen and operator new call, wrapped in this program around glibc's: a step should make none
// inside a step).
// Usage: solver_scaling_benchmark [BODIES STEPS [linear|stiffened]]: one chain, for profiling.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "benchmarks/allocation_count.h"
#include "formats/part_file.h"
#include "reducer/reduce_part.h"
#include "solver/analysis/dynamic_analysis.h"
#include "solver/parallel.h"

int main(int argc, char** argv) {
  std::vector<int> chains = {1, 10, 100, 1000};
  int fixed_steps = 0;
  std::vector<bool> kinds = {false, true};
  if (argc >= 3) {
    chains = {std::max(1, std::atoi(argv[1]))};
    fixed_steps = std::max(1, std::atoi(argv[2]));
    if (argc >= 4) kinds = {std::string(argv[3]) == "stiffened"};
  }
  std::printf("Solver scaling: chain of N tube superelements (2 modes each), clamped, gravity, generalized-alpha\n\n");
  const int threads = femb::DefaultThreads();
  std::printf("%6s %-11s %12s %10s %14s %16s %18s %8s %18s %16s\n", "bodies", "bodies are", "coordinates", "steps",
              "s per step", "Newton its/step", "ms per step/body", "ratio", "speed-up, threads", "allocs/body-step");
  for (int n_bodies : chains) {
    double linear_ms = 0.0;
    for (bool stiffening : kinds) {
      const double Lb = 1.0 / n_bodies;
      const femb::PartSpec part = femb::ParsePart(
          "name: seg\ntype: beam\nmaterial: {E: 70.0e9, nu: 0.3, rho: 2700}\n"
          "section: {shape: tube, outer_radius: 0.01, wall: 0.001}\n"
          "beam:\n  points: {A: [0, 0, 0], B: [" +
              std::to_string(Lb) +
              ", 0, 0]}\n"
              "  segments: [{from: A, to: B, elements: 2}]\n"
              "interfaces: [{name: A}, {name: B}]\nreduction: {internal_modes: 2, keep_mesh: false, "
              "geometric_stiffening: " +
              std::string(stiffening ? "true" : "false") + "}\n",
          "bench.yaml");
      const femb::ReduceResult reduced = femb::ReducePart(part, nullptr);
      if (!reduced.ok) return 3;
      femb::SystemModel model;
      for (int i = 0; i <= n_bodies; ++i) femb::AddNode(model, "n" + std::to_string(i), Eigen::Vector3d(i * Lb, 0, 0));
      femb::Clamp(model, 0);
      for (int i = 0; i < n_bodies; ++i) {
        model.bodies.emplace_back(reduced.superelement, femb::SuperelementOptions{}, Eigen::Matrix3d::Identity(),
                                  Eigen::Vector3d(i * Lb, 0, 0));
        model.body_nodes.push_back({i, i + 1});
      }
      model.gravity = Eigen::Vector3d(0, -9.81, 0);
      model.Number();
      const femb::DofMap& dofs = model.dofs();
      const int steps = fixed_steps > 0    ? fixed_steps
                        : n_bodies >= 1000 ? 5
                        : n_bodies >= 100  ? 50
                                           : 200;  // small chains: more steps, less noise
      // One run on `t` threads: seconds, the result.
      auto run = [&](int t, femb::DynamicResult* r) {
        femb::DynamicState s =
            femb::InitialDynamicState(model, femb::InitialState(model), Eigen::VectorXd::Zero(dofs.n_dofs()));
        femb::DynamicOptions options;
        options.step = 1e-3;
        options.end_time = steps * options.step;
        options.rho_inf = 0.8;
        options.threads = t;
        const auto start = std::chrono::steady_clock::now();
        *r = femb::SolveDynamic(model, s, options);
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      };
      femb::DynamicResult r, r_many;
      const long allocations_before = femb_allocations.load();
      const double seconds = run(1, &r);
      const long allocations = femb_allocations.load() - allocations_before;
      if (!r.ok) {
        std::printf("%6d %-11s failed: %s\n", n_bodies, stiffening ? "stiffened" : "linear", r.message.c_str());
        continue;
      }
      const double seconds_many = threads > 1 ? run(threads, &r_many) : seconds;
      const double ms = 1e3 * seconds / r.steps / n_bodies;
      if (!stiffening) linear_ms = ms;
      std::printf("%6d %-11s %12d %10ld %14.4f %16.2f %18.3f %8.2f %14.2f, %d %16.0f\n", n_bodies,
                  stiffening ? "stiffened" : "linear", dofs.n_dofs(), r.steps, seconds / r.steps,
                  double(r.newton_iterations) / r.steps, ms, linear_ms > 0 ? ms / linear_ms : 1.0,
                  seconds / seconds_many, threads, double(allocations) / double(r.steps) / n_bodies);
      std::fflush(stdout);
    }
  }
  return 0;
}
