// Static analysis: load stepping on the load factor lambda in [0, 1] (or a given list), Newton
// with the full tangent at each step, step cutting on divergence (thesis 4.2).
#pragma once

#include <atomic>
#include <functional>
#include <string>
#include <vector>

#include "solver/assembly/system.h"

namespace femb {

struct StaticOptions {
  /// A stop request, read after each converged step: nonzero stops the run there
  /// (StaticResult::stopped; femb-solve: solver/stop_request.h).
  const std::atomic<int>* stop = nullptr;
  double end_time = 1.0;    ///< pseudo-time at the end; loads are scaled by their functions of it
  int steps = 10;           ///< equal pseudo-time steps to end_time
  int max_iterations = 25;  ///< Newton iterations per step
  int max_cuts = 6;         ///< halvings of a step before giving up
  double tolerance = 1e-8;  ///< ||residual|| <= tol * (largest force term of the step); at least kRoundOffTolerance
  int threads = 1;          ///< bodies evaluated in parallel on this many threads (the same results for any number)
};

struct StaticStepReport {
  double lambda = 0.0;  ///< pseudo-time
  int iterations = 0;
  double residual = 0.0;
  double elastic_energy = 0.0;
  double external_work = 0.0;  ///< work of the nodal loads so far (trapezoidal rule per step)
  /// The converged pass's forces on the nodes (residual sense), at the step's state: what
  /// JointReactions needs, without assembling again. Valid during the callback.
  const NodeForces* node_forces = nullptr;
};

struct StaticResult {
  bool ok = false;
  std::string message;  ///< why it stopped early
  int stopped = 0;      ///< the stop request's value when it stopped on it (ok), else 0
  /// Said once each: the tangent's determinant changed sign (a limit or bifurcation point), a
  /// tolerance below the round-off floor.
  std::vector<std::string> warnings;
  std::vector<StaticStepReport> steps;  ///< converged steps
};

/// Runs the load stepping from `state` (updated to the last converged step). `on_step` is
/// called after each converged step (output writing, progress).
StaticResult SolveStatic(const SystemModel& model, SystemState& state, const StaticOptions& options,
                         const std::function<void(const StaticStepReport&, const SystemState&)>& on_step = nullptr);

}  // namespace femb
