#include "solver/analysis/static_analysis.h"

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>

#include "solver/analysis/singularity.h"
#include "solver/assembly/body_pass.h"
#include "solver/parallel.h"

namespace femb {
namespace {

// Negative eigenvalues of the symmetric part of S on the free coordinates (inertia of a pivoted
// LDL^T), or -1 above the dense limit.
int NegativeEigenvalues(const DofMap& dofs, const SystemMatrix& S) {
  const int n = int(dofs.solved().size());
  if (n == 0 || n > kDenseLimit) return -1;
  const Eigen::MatrixXd A = DenseFreeMatrix(dofs, S);
  const Eigen::MatrixXd sym = 0.5 * (A + A.transpose());
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(sym);
  int negative = 0;
  for (int i = 0; i < n; ++i) negative += ldlt.vectorD()[i] < 0;
  return negative;
}

// The minimum-norm Newton step of a singular tangent whose free motions the residual does not
// drive: S scaled to unit diagonal (D S D, as DescribeSingular), its SVD, rank at 1e-13 of the
// largest singular value; when the residual's part along the left null vectors is within 1e-8 of
// its size, the truncated pseudo-inverse's step. A pendulum hanging from its pin, started
// unstretched, has no stiffness against swinging until its weight has stretched it (the tension's
// geometric stiffness): its first step is this one, along the rod, and the next tangent is
// regular. False above the dense limit or when the residual drives a free motion (a missing
// support: the caller names it).
bool MinimumNormStep(const DofMap& dofs, const SystemMatrix& S, const Eigen::VectorXd& residual,
                     Eigen::VectorXd* delta) {
  const std::vector<int>& free = dofs.solved();
  const int n = int(free.size());
  if (n == 0 || n > kDenseLimit) return false;
  const Eigen::MatrixXd A = DenseFreeMatrix(dofs, S);
  Eigen::VectorXd d(n), r(n);
  for (int i = 0; i < n; ++i) {
    const double a = std::abs(A(i, i));
    d[i] = a > 0 ? 1.0 / std::sqrt(a) : 1.0;
    r[i] = d[i] * residual[free[size_t(i)]];
  }
  const Eigen::BDCSVD<Eigen::MatrixXd> svd(d.asDiagonal() * A * d.asDiagonal(),
                                           Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::VectorXd& sv = svd.singularValues();
  int rank = 0;
  while (rank < n && sv[rank] > 1e-13 * sv[0]) ++rank;
  if (rank == n || rank == 0) return false;
  const Eigen::VectorXd driven = svd.matrixU().rightCols(n - rank).transpose() * r;
  if (driven.norm() > 1e-8 * r.norm()) return false;
  const Eigen::VectorXd step =
      d.asDiagonal() *
      (svd.matrixV().leftCols(rank) * (svd.matrixU().leftCols(rank).transpose() * r).cwiseQuotient(sv.head(rank)));
  *delta = Eigen::VectorXd::Zero(dofs.n_dofs());
  for (int i = 0; i < n; ++i) (*delta)[free[size_t(i)]] = step[i];
  return delta->allFinite();
}

}  // namespace

namespace {

// Stability along the load path: the negative eigenvalues of the tangent's symmetric part at the
// start of each step (Sylvester's inertia of its pivoted LDL^T; dense systems only). A change
// between two steps is a limit point or a bifurcation, also a double one (a column of round
// section buckles in two planes at once: det(K) keeps its sign there). Said up to 5 times.
class StabilityWatch {
 public:
  void Check(const DofMap& dofs, const SystemMatrix& tangent, double target, std::vector<std::string>& warnings) {
    const int negative = NegativeEigenvalues(dofs, tangent);
    if (negative >= 0 && last_negative_ >= 0 && negative != last_negative_ && reports_++ < 5) {
      char buffer[400];
      std::snprintf(buffer, sizeof buffer,
                    "the tangent's negative eigenvalues went from %d to %d between pseudo-time %.6g and %.6g: "
                    "a limit or bifurcation point (snap-through or buckling) was crossed%s",
                    last_negative_, negative, last_lambda_, target,
                    negative > last_negative_ ? "; a perfect structure stays on its unstable branch (add an "
                                                "imperfection to follow the buckled one)"
                                              : "");
      warnings.push_back(buffer);
    }
    last_negative_ = negative;
    last_lambda_ = target;
  }

 private:
  int last_negative_ = -1;
  double last_lambda_ = 0.0;
  int reports_ = 0;
};

// Newton's iterations of one load step, from `trial` at load factor `target`.
struct StaticNewton {
  bool converged = false;
  int iterations = 0;
  double r_norm = 0.0, energy = 0.0;
  Eigen::VectorXd travelled, loads_after;  ///< the step's motion and the loads at its end
  NodeForces node_forces;                  ///< the converged pass's (for the reactions)
};

// The passes' storage and threads of a static run.
struct StaticPasses {
  StaticWorkspace work;
  BodyThreads threads;
  explicit StaticPasses(int n) : threads(n) {}
  BodyThreads* pool() { return threads.threads() > 1 ? &threads : nullptr; }
};

// Newton on the static residual at load factor `target` from `trial` (moved in place). At the run's
// first step a singular tangent is the model's, not the step's: it names the free motion in
// *fatal instead of cutting steps -- unless the loads do not drive it and one minimum-norm step
// makes the tangent regular (MinimumNormStep). Increments below round-off of the positions
// (`size` the model's) also mean convergence: an unloaded state has a residual of round-off size
// and no force scale to compare it with.
StaticNewton NewtonSteps(const SystemModel& model, const DofMap& dofs, const StaticOptions& options, double target,
                         double size, double tolerance, const Eigen::VectorXd& weights, bool first_step,
                         SystemState& trial, StabilityWatch& stability, StaticPasses& passes, StaticResult& result,
                         std::string* fatal) {
  StaticNewton out;
  double last_step = 1e300;
  out.travelled = Eigen::VectorXd::Zero(dofs.n_dofs());
  bool minimum_norm = false;  // the first step of the run was MinimumNormStep's
  for (; out.iterations < options.max_iterations; ++out.iterations) {
    const int it = out.iterations;
    const SystemForces f = AssembleStatic(model, dofs, trial, target, true, &passes.work, passes.pool());
    if (!f.ok) break;
    out.r_norm = FreeNorm(dofs, f.residual, weights);
    out.energy = f.elastic_energy;
    out.loads_after = f.loads;
    if (!std::isfinite(out.r_norm)) break;
    if (it > 0 && LoopsClosed(model, trial, tolerance) &&
        (out.r_norm <= f.roundoff || ScaledFreeNorm(dofs, f.residual, weights, f.dof_scale) <= tolerance ||
         last_step <= 1e-13 * size)) {
      out.converged = true;
      out.node_forces = f.node_forces;
      break;
    }
    FreeSolver solver;
    const bool regular = solver.Factor(dofs, f.tangent);
    if (regular && it == 0) stability.Check(dofs, f.tangent, target, result.warnings);
    Eigen::VectorXd delta = regular ? solver.Solve(f.residual) : Eigen::VectorXd();
    if (!regular || !delta.allFinite()) {
      if (first_step && (it == 0 || (it == 1 && minimum_norm))) {
        const std::string why = DescribeSingular(model, dofs, trial, f.tangent);
        if (!why.empty()) {
          if (it == 0 && MinimumNormStep(dofs, f.tangent, f.residual, &delta)) {
            minimum_norm = true;
            last_step = delta.head(dofs.first_multiplier()).norm();
            out.travelled += delta;
            ApplyIncrement(model, dofs, delta, trial);
            continue;
          }
          *fatal = "static tangent at the start: " + why;
          return out;
        }
      }
      break;
    }
    last_step = delta.head(dofs.first_multiplier()).norm();  // coordinates, not multipliers
    out.travelled += delta;
    ApplyIncrement(model, dofs, delta, trial);
  }
  return out;
}

}  // namespace

StaticResult SolveStatic(const SystemModel& model, SystemState& state, const StaticOptions& options,
                         const std::function<void(const StaticStepReport&, const SystemState&)>& on_step) {
  StaticResult result;
  const DofMap& dofs = model.dofs();
  const double end = options.end_time, nominal = options.end_time / options.steps;
  double size = 0.0;
  for (const Eigen::Vector3d& x : model.node_x0) size = std::max(size, x.norm());
  if (size == 0.0) size = 1.0;
  double lambda = 0.0, step = nominal, work = 0.0;
  Eigen::VectorXd loads_before = Eigen::VectorXd::Zero(dofs.n_dofs());
  int cuts = 0;
  const double tolerance = std::max(options.tolerance, kRoundOffTolerance);
  const Eigen::VectorXd weights = ResidualWeights(model, dofs);
  if (const std::string w = RoundOffToleranceWarning(options.tolerance); !w.empty()) result.warnings.push_back(w);
  StabilityWatch stability;
  StaticPasses passes(options.threads);
  while (lambda < end * (1 - 1e-12)) {
    const double target = std::min(end, lambda + step);
    SystemState trial = state;
    ApplyPrescribed(model, dofs, target, trial, nullptr, nullptr);
    std::string fatal;
    const StaticNewton newton = NewtonSteps(model, dofs, options, target, size, tolerance, weights,
                                            result.steps.empty(), trial, stability, passes, result, &fatal);
    if (!fatal.empty()) {
      result.message = fatal;
      return result;
    }
    if (!newton.converged) {
      if (cuts >= options.max_cuts) {
        char buffer[200];
        std::snprintf(buffer, sizeof buffer,
                      "Newton did not converge at pseudo-time %.6g after %d step cuts (last residual %.3g)", target,
                      cuts, newton.r_norm);
        result.message = buffer;
        return result;
      }
      step *= 0.5;
      ++cuts;
      continue;
    }
    // Prescribed coordinates moved too (ApplyPrescribed): their loads are reactions, not counted.
    work += 0.5 * (loads_before + newton.loads_after).dot(newton.travelled);
    loads_before = newton.loads_after;
    state = trial;
    lambda = target;
    StaticStepReport report{lambda, newton.iterations, newton.r_norm, newton.energy, work};
    result.steps.push_back(report);  // without the pass's node forces: they live for this step
    report.node_forces = &newton.node_forces;
    if (on_step) on_step(report, state);
    if (options.stop && options.stop->load() != 0) {
      result.stopped = options.stop->load();
      break;
    }
    // Grow back towards the nominal step after easy steps.
    if (newton.iterations <= 4 && cuts > 0) {
      step = std::min(nominal, 2.0 * step);
      --cuts;
    }
  }
  result.ok = true;
  return result;
}

}  // namespace femb
