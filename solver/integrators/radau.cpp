// The three-stage Radau IIA integrator (Hairer & Wanner 1996, IV.5; order 5, stiffly accurate,
// L-stable) on the Lie group of the nodes in the form of Munthe-Kaas (1999): the stages are
// configurations q_n o exp(Theta_i), the local coordinates Theta_i integrated by the same
// tableau with the inverse left Jacobian of the rotation triples, Theta_i' = J_l^-1(Theta_i) W.
// Per stage i (c_i its time fraction, a_ij the tableau):
//
//     V_i     = W_n + h sum_j a_ij A_j                        (stage velocities)
//     Theta_i = h sum_j a_ij J_l^-1(Theta_j) V_j             (rotation triples)
//             = h c_i W_n + h^2 sum_j (a^2)_ij A_j            (every other unknown: additive)
//     r(q_n o exp(Theta_i), V_i, A_i, t_n + c_i h) = 0        (the equations of motion)
//
// solved for the stage accelerations A_j by Newton, the iteration matrix's block (i, j)
// delta_ij M_i + h a_ij C_i + h^2 (a^2)_ij K_i with stage i's own K, C and M (the bodies' mass
// and gyroscopic matrices computed at the first stage and turned to the others: KeptMatricesOf),
// factored once a step (again when an iteration contracts less than tenfold). The last stage is
// the step's end (c_3 = 1): the state, its velocity and acceleration. The stage residuals are the dynamic
// residual of generalized-alpha (AssembleDynamicResidual), so every body kind, force and joint
// comes with it. Closed loops and interface constraints: each stage has its own multipliers
// Lambda_i (held in the multipliers' entries of A_i), and its constraint equations
// g(q_n o exp(Theta_i)) = 0 (the index-3 stage system of Hairer and Wanner, VII.4), their rows
// scaled by 1 / h^2 in the iteration matrix.
#include <Eigen/SparseLU>
#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <utility>

#include "solver/analysis/dynamic_step.h"
#include "solver/rotation.h"

namespace femb::dynamic_internal {

namespace {

// The Radau IIA tableau of order 5: c, a and a^2 (the positions' weights of the accelerations).
struct RadauTableau {
  std::array<double, 3> c{};
  double a[3][3]{}, a2[3][3]{};
  RadauTableau() {
    const double s6 = std::sqrt(6.0);
    c = {(4 - s6) / 10, (4 + s6) / 10, 1.0};
    const double values[3][3] = {{(88 - 7 * s6) / 360, (296 - 169 * s6) / 1800, (-2 + 3 * s6) / 225},
                                 {(296 + 169 * s6) / 1800, (88 + 7 * s6) / 360, (-2 - 3 * s6) / 225},
                                 {(16 - s6) / 36, (16 + s6) / 36, 1.0 / 9}};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) a[i][j] = values[i][j];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        a2[i][j] = 0.0;
        for (int k = 0; k < 3; ++k) a2[i][j] += a[i][k] * a[k][j];
      }
  }
  /// Lagrange's basis polynomial of node c_j at s (in the step's time fraction).
  double Lagrange(int j, double s) const {
    double l = 1.0;
    for (int k = 0; k < 3; ++k)
      if (k != j) l *= (s - c[size_t(k)]) / (c[size_t(j)] - c[size_t(k)]);
    return l;
  }
};

const RadauTableau& Tableau() {
  static const RadauTableau tableau;
  return tableau;
}

// The stages' local coordinates Theta_i and velocities V_i from the accelerations A_j (above).
// The rotation triples' Theta_i are a fixed point of Theta = h a J_l^-1(Theta) V: iterated from
// the additive value, each pass contracting by about |h omega| (converged to round-off in a few).
void StageKinematics(const DofMap& dofs, const DynamicState& state, double h, RadauWorkspace& r,
                     const std::vector<RotationNode>& rotations) {
  const RadauTableau& t = Tableau();
  for (int i = 0; i < 3; ++i) {
    r.V[size_t(i)] = state.W;
    r.theta[size_t(i)] = (h * t.c[size_t(i)]) * state.W;
    for (int j = 0; j < 3; ++j) {
      r.V[size_t(i)] += (h * t.a[i][j]) * r.A[size_t(j)];
      r.theta[size_t(i)] += (h * h * t.a2[i][j]) * r.A[size_t(j)];
    }
    dofs.ClearMultipliers(r.V[size_t(i)]);
    dofs.ClearMultipliers(r.theta[size_t(i)]);
  }
  constexpr int kPasses = 4;
  for (const RotationNode& n : rotations) {
    std::array<Eigen::Vector3d, 3> theta, v;
    for (int i = 0; i < 3; ++i) {
      theta[size_t(i)] = r.theta[size_t(i)].segment<3>(n.rotation);
      v[size_t(i)] = r.V[size_t(i)].segment<3>(n.rotation);
    }
    for (int pass = 0; pass < kPasses; ++pass) {
      std::array<Eigen::Vector3d, 3> rate;
      for (int j = 0; j < 3; ++j) rate[size_t(j)] = LeftJacobianInverse<double>(theta[size_t(j)]) * v[size_t(j)];
      for (int i = 0; i < 3; ++i) {
        theta[size_t(i)].setZero();
        for (int j = 0; j < 3; ++j) theta[size_t(i)] += (h * t.a[i][j]) * rate[size_t(j)];
      }
    }
    for (int i = 0; i < 3; ++i) r.theta[size_t(i)].segment<3>(n.rotation) = theta[size_t(i)];
  }
}

// The predictor: the last step's collocation polynomial of the accelerations (the quadratic
// through its stage accelerations) extrapolated to this step's stages; the accelerations constant
// over the step at the start (no last step kept).
void Predict(const DynamicState& state, double h, RadauWorkspace& r) {
  const RadauTableau& t = Tableau();
  if (state.increments_kept < 3) {
    for (int i = 0; i < 3; ++i) {
      r.A[size_t(i)] = state.Wdot;
      if (state.config.lambda.size() > 0) r.A[size_t(i)].tail(state.config.lambda.size()) = state.config.lambda;
    }
    return;
  }
  const double h_last = state.increment_steps[0];
  for (int i = 0; i < 3; ++i) {
    const double s = 1.0 + t.c[size_t(i)] * h / h_last;  // in the last step's time fraction
    r.A[size_t(i)].setZero(state.Wdot.size());
    for (int j = 0; j < 3; ++j) r.A[size_t(i)] += t.Lagrange(j, s) * state.increments[size_t(j)];
  }
}

// Stage i's state: q_n o exp(Theta_i) with the prescribed coordinates at their values at t_i
// (one kinematic update for both), V_i and A_i with the prescribed rates and accelerations.
void PlaceStage(const SystemModel& model, const DofMap& dofs, const DynamicState& state, double t_i, int i, bool first,
                RadauWorkspace& r) {
  DynamicState& s = r.stage[size_t(i)];
  Eigen::VectorXd& theta = r.theta[size_t(i)];
  s.W = r.V[size_t(i)];
  s.Wdot = r.A[size_t(i)];
  dofs.ClearMultipliers(s.Wdot);
  PrescribedIncrements(model, dofs, t_i, state.config, theta, &s.W, &s.Wdot);
  // The bodies' frames solved from the stage's last iterate in this step, from the step's start
  // at its first iterate (not from the last step's stage: a run resumed from a checkpoint has
  // none, and takes the same steps to the bit).
  const bool warm = !first && s.config.frames.size() == state.config.frames.size();
  if (warm) r.frames = s.config.frames;
  s.config = state.config;
  if (warm) s.config.frames = r.frames;
  ApplyIncrement(model, dofs, theta, s.config);
  if (dofs.n_multipliers() > 0) s.config.lambda = r.A[size_t(i)].tail(dofs.n_multipliers());
  s.t = t_i;
}

// The scale of unknown j's equation in the iteration matrix and its right-hand side: 1 / h^2 on a
// multiplier's (a constraint equation, index 3), 1 on the others.
double RowScale(const DofMap& dofs, int j, double h) { return dofs.multiplier(j) ? 1.0 / (h * h) : 1.0; }

// Calls add(row, col, value, row_scale, multiplier_column) for each entry of X between solved
// unknowns (row and col their places among the solved ones, `position`), with its row's RowScale.
template <class Add>
void SolvedEntries(const DofMap& dofs, const std::vector<int>& position, const SystemMatrix& X, double h, Add&& add) {
  for (int col = 0; col < X.outerSize(); ++col) {
    const int c = position[size_t(col)];
    if (c < 0) continue;
    const bool multiplier_column = dofs.multiplier(col);
    for (SystemMatrix::InnerIterator it(X, col); it; ++it) {
      const int row = position[size_t(it.row())];
      if (row >= 0) add(row, c, it.value(), RowScale(dofs, int(it.row()), h), multiplier_column);
    }
  }
}

// The iteration matrix over the stages' solved unknowns (stage i's unknown k at i n_solved + k),
// block (i, j) = delta_ij M_i + h a_ij C_i + h^2 (a^2)_ij K_i with stage i's K, C and M
// (r.assembly[i]), factored: dense up to kDenseStages unknowns, sparse above. False when singular.
bool FactorStageMatrix(const DofMap& dofs, double h, RadauWorkspace& r) {
  const RadauTableau& t = Tableau();
  const std::vector<int>& solved = dofs.solved();
  const int n = int(solved.size());
  r.position.assign(size_t(dofs.n_dofs()), -1);
  for (int k = 0; k < n; ++k) r.position[size_t(solved[size_t(k)])] = k;
  r.J.Start(3 * n, 3 * n <= RadauWorkspace::kDenseStages);
  // A multiplier's column is stage j's own unknown Lambda_j (in stage j's equations alone, its
  // K entry as it is); a multiplier's row (a constraint equation) is scaled (RowScale).
  const auto add = [&](int i, const SystemMatrix& X, int which) {
    SolvedEntries(dofs, r.position, X, h, [&](int row, int c, double value, double row_scale, bool multiplier_column) {
      for (int j = 0; j < 3; ++j) {
        double f = which == 0 ? (i == j ? 1.0 : 0.0) : which == 1 ? h * t.a[i][j] : h * h * t.a2[i][j];
        if (multiplier_column) f = i == j ? 1.0 : 0.0;
        f *= row_scale;
        if (f != 0.0) r.J.Add(i * n + row, j * n + c, f * value);
      }
    });
  };
  for (int i = 0; i < 3; ++i) {
    const Assembly& a = r.assembly[size_t(i)];
    add(i, a.M, 0);
    add(i, a.C, 1);
    add(i, a.K, 2);
  }
  r.factored = r.J.Factor();
  return r.factored;
}

// How a matrix build keeps the bodies' matrices (AddDynamicMatrices' `every`, counted in stage
// passes, and `which`); `restart`: the first stage computes them all whatever their age.
struct KeptMatrices {
  int every = 1;
  BodyMatricesKept which = BodyMatricesKept::kAll;
  bool restart = false;
};

// Stage i's K, C and M at its iterate, from the pass just assembled (the next stage's pass
// replaces it), into r.assembly[i]; built by the stage's own triplet assemblers, whose patterns
// then stay from step to step (a loop's blocks differ between the stages' configurations).
void StageMatrices(const SystemModel& model, const DofMap& dofs, const DynamicOptions& options, double t_i, int i,
                   bool first, const KeptMatrices& kept, BodyThreads& threads, BodyWorkspace& work) {
  RadauWorkspace& r = work.radau;
  if (kept.restart && first)
    for (BodyWorkspace::BodyMatrices& m : work.matrices) m.age = -1;
  work.K_build.swap(r.K_build[size_t(i)]);
  work.C_build.swap(r.C_build[size_t(i)]);
  work.M_build.swap(r.M_build[size_t(i)]);
  AddDynamicMatrices(model, dofs, r.stage[size_t(i)], t_i, work, options.full_inertia_tangent, r.assembly[size_t(i)],
                     &threads, nullptr, kept.every, kept.which);
  work.K_build.swap(r.K_build[size_t(i)]);
  work.C_build.swap(r.C_build[size_t(i)]);
  work.M_build.swap(r.M_build[size_t(i)]);
}

// The bodies' matrices of this matrix build. With body_matrices_every k > 1 a step's first build
// may take the kept ones of up to k steps ago (which ones: body_matrices_kept). Otherwise, and in
// a step's later builds, each body's mass and gyroscopic matrices are computed at the build's
// first stage (the first; the last in RefreshStageMatrices) and turned with the floating frame to
// the other two: the inertia force is objective, so they differ between the stages only by the
// change of the deformation and of the velocities in the frame within the step (the
// slider-crank's Newton iterations at 0.75-2 ms steps are the same as with each stage's own, at
// 0.87x the time). The tangents, which carry the stage's internal forces and accelerations, are
// computed at every stage. jacobian_reuse: none computes them all.
KeptMatrices KeptMatricesOf(const DynamicOptions& options, JacobianReuse reuse, bool factored) {
  if (reuse == JacobianReuse::kNone) return {};
  if (!factored && options.body_matrices_every > 1)
    return {3 * options.body_matrices_every, options.body_matrices_kept};
  return {3, BodyMatricesKept::kInertia, true};
}

// Error control: the step's local error by an embedded formula of third order (Hairer & Wanner
// IV.8, in the second-order form): the velocities v^ = v_n + h (g a_n + sum_j b^_j A_j), with
// g = 0.2749 (the real eigenvalue of the tableau's a, 1 / 3.6378) and the b^ that make it exact
// for accelerations of degree 2. Radau's own weights b (on the stages alone) are exact to degree 4,
// so the two differ by e_v = g h (a_n - P(0)), P the quadratic through the stage accelerations
// (the collocation polynomial) at the step's start: O(h^3) for a smooth motion, e_v O(h^4).
// The estimate is filtered by (I - g h J)^-1 in the first-order form (q, v), as Radau5 does: the
// stiff directions, whose stage accelerations follow a transient that the scheme damps (L-stable),
// would otherwise set the step. With no error in the positions' formula that is
//   (M + g h C + g^2 h^2 K) y = M e_v,   x = g h y   (x, y: the positions' and velocities' errors),
// M, C, K the last stage's (constraint rows as in the iteration matrix, their right-hand side 0,
// so that the error lies along the constraints). Into r.error_q = x and r.error_v = h y (what the
// velocities' error moves the positions over a step): both O(h^5). Unfiltered (y = e_v) where the
// filter's matrix is singular.
void RadauLocalError(const DofMap& dofs, const DynamicState& state, double h, RadauWorkspace& r) {
  const RadauTableau& t = Tableau();
  constexpr double g = 0.27488882959;  // the real eigenvalue of a, 1 / 3.6378342
  const std::vector<int>& solved = dofs.solved();
  const int n = int(solved.size());
  r.d = state.Wdot;
  for (int j = 0; j < 3; ++j) r.d -= t.Lagrange(j, 0.0) * r.A[size_t(j)];
  for (int j = 0; j < dofs.n_dofs(); ++j)
    if (r.position[size_t(j)] < 0 || dofs.multiplier(j)) r.d[j] = 0.0;
  const Assembly& a = r.assembly[2];
  r.product.noalias() = a.M * r.d;
  r.filter_rhs.setZero(n);
  for (int k = 0; k < n; ++k)
    if (!dofs.multiplier(solved[size_t(k)])) r.filter_rhs[k] = g * h * r.product[solved[size_t(k)]];
  r.filter.Start(n, n <= RadauWorkspace::kDenseStages / 3);
  const auto add = [&](const SystemMatrix& X, double coefficient) {
    SolvedEntries(dofs, r.position, X, h, [&](int row, int c, double value, double row_scale, bool multiplier_column) {
      r.filter.Add(row, c, (multiplier_column ? 1.0 : coefficient) * row_scale * value);
    });
  };
  add(a.M, 1.0);
  add(a.C, g * h);
  add(a.K, g * g * h * h);
  const bool filtered = r.filter.Factor();
  if (filtered) r.filter.Solve(r.filter_rhs, r.filtered);
  if (!filtered || !r.filtered.allFinite()) {
    r.filtered.resize(n);
    for (int k = 0; k < n; ++k) r.filtered[k] = g * h * r.d[solved[size_t(k)]];
  }
  r.error_q.setZero(dofs.n_dofs());
  r.error_v.setZero(dofs.n_dofs());
  for (int k = 0; k < n; ++k) {
    const int j = solved[size_t(k)];
    if (dofs.multiplier(j)) continue;
    r.error_q[j] = g * h * r.filtered[k];
    r.error_v[j] = h * r.filtered[k];
  }
}

// The converged step's end into `next`: the last stage's state, with the works of the loads and
// drives by the stages' quadrature (order 5), h sum_i b_i f_i . V_i (b the tableau's last row),
// and the stage accelerations for the next step's predictor. Field by field: `next` keeps its
// storage.
void FinishStep(const DofMap& dofs, const DynamicState& state, double h, double t_new, RadauWorkspace& r,
                DynamicState& next) {
  const RadauTableau& t = Tableau();
  const DynamicState& end = r.stage[2];
  next.config = end.config;
  next.W = end.W;
  next.Wdot = end.Wdot;
  next.node_w.clear();
  next.t = t_new;
  next.a = next.Wdot;
  next.external_work = state.external_work;
  next.drive_work = state.drive_work;
  for (int i = 0; i < 3; ++i) {
    const Assembly& a = r.assembly[size_t(i)];
    next.external_work += h * t.a[2][i] * a.f_ext.dot(r.stage[size_t(i)].W);
    DriveForces(dofs, a.residual, r.f_drive);
    next.drive_work += h * t.a[2][i] * r.f_drive.dot(r.stage[size_t(i)].W);
  }
  for (int i = 0; i < 3; ++i) {
    next.increments[size_t(i)] = r.A[size_t(i)];
    next.increment_steps[size_t(i)] = h;
  }
  next.increments_kept = 3;
  next.f_ext = r.assembly[2].f_ext;
  next.f_drive = r.f_drive;
}

// The stages' residuals at the current accelerations r.A (their kinematics, placement and pass),
// with each stage's matrices (StageMatrices) when `matrices`; their largest weighted norm, and
// whether all are small and the loops closed.
struct StageResiduals {
  bool ok = true, small = true, closed = true;
  double r_max = 0.0;
};

StageResiduals EvaluateStages(const SystemModel& model, const DofMap& dofs, const DynamicOptions& options,
                              const DynamicState& state, double h, double t_new, bool first, double tolerance,
                              const KeptMatrices* matrices, BodyThreads& threads, BodyWorkspace& work) {
  const RadauTableau& t = Tableau();
  RadauWorkspace& r = work.radau;
  const Eigen::VectorXd& weights = work.Weights(model, dofs);
  StageKinematics(dofs, state, h, r, work.rotation_triples);
  StageResiduals out;
  for (int i = 0; i < 3; ++i) {
    const double t_i = i == 2 ? t_new : state.t + t.c[size_t(i)] * h;
    PlaceStage(model, dofs, state, t_i, i, first, r);
    Assembly& a = r.assembly[size_t(i)];
    AssembleDynamicResidual(model, dofs, r.stage[size_t(i)], t_i, work, &threads, a);
    if (!a.ok || !a.residual.allFinite()) {
      out.ok = false;
      return out;
    }
    const double r_norm = FreeNorm(dofs, a.residual, weights);
    out.r_max = std::max(out.r_max, r_norm);
    out.small = out.small && ResidualSmall(dofs, a, weights, r_norm, tolerance);
    // The loops at this stage, with its bodies' data (the pass just assembled).
    if (model.has_constraints())
      out.closed =
          out.closed && LoopsClosed(model, r.stage[size_t(i)].config, tolerance, &work.pass_data, &work.parts.scratch);
    if (matrices) StageMatrices(model, dofs, options, t_i, i, i == 0, *matrices, threads, work);
  }
  return out;
}

// The stages' matrices anew at the current iterate, decided after its residuals: the last stage's
// first, from its pass (the one just assembled), then the other two stages' passes again, each
// followed by its matrices (the bodies' mass and gyroscopic matrices the last stage's, turned).
// False when a pass fails.
bool RefreshStageMatrices(const SystemModel& model, const DofMap& dofs, const DynamicOptions& options,
                          const DynamicState& state, double h, double t_new, const KeptMatrices& kept,
                          BodyThreads& threads, BodyWorkspace& work) {
  const RadauTableau& t = Tableau();
  RadauWorkspace& r = work.radau;
  StageMatrices(model, dofs, options, t_new, 2, true, kept, threads, work);
  for (int i = 0; i < 2; ++i) {
    const double t_i = state.t + t.c[size_t(i)] * h;
    Assembly& a = r.assembly[size_t(i)];
    AssembleDynamicResidual(model, dofs, r.stage[size_t(i)], t_i, work, &threads, a);
    if (!a.ok || !a.residual.allFinite()) return false;
    StageMatrices(model, dofs, options, t_i, i, false, kept, threads, work);
  }
  return true;
}

// The stages' largest residual relative to the forces on each unknown (ScaledFreeNorm, Newton's
// measure), from their last passes.
double LargestScaledResidual(const SystemModel& model, const DofMap& dofs, BodyWorkspace& work) {
  const Eigen::VectorXd& weights = work.Weights(model, dofs);
  double largest = 0.0;
  for (const Assembly& a : work.radau.assembly)
    largest = std::max(largest, ScaledFreeNorm(dofs, a.residual, weights, a.dof_scale));
  return largest;
}

// Newton's first correction leaves the residual above this many times the tolerance: the predictor
// was far from the solution, and so were the forces its matrices carry (a rod's stiff axial force,
// whose geometric stiffness sets its transverse directions). The next corrections then contract
// little with them (the slider-crank's rod at 2 ms steps: 38 -> 25 N, where fresh ones give
// 38 -> 1.5 N), so the matrices are computed anew at the first iterate. Measured, with the kept
// matrices: of the steps whose first correction left the residual above 30x the tolerance, 59 of
// 61 contracted less than tenfold (the example's rod at 2 ms), 10 of 17 (tube bodies at 2 ms);
// of those between 10x and 30x, 1 of 1 and 1 of 26: below 30x the kept ones mostly serve.
constexpr double kFarFromSolution = 30.0;

}  // namespace

Eigen::VectorXd RadauStageResiduals(const SystemModel& model, const DofMap& dofs, const DynamicOptions& options,
                                    const DynamicState& state, double h, const std::array<Eigen::VectorXd, 3>& A,
                                    BodyWorkspace& work, Eigen::MatrixXd* matrix) {
  RadauWorkspace& r = work.radau;
  BodyThreads threads;
  work.inertia_factor = 0.0;
  r.A = A;
  const KeptMatrices all;  // each stage's own matrices, every body's computed
  const StageResiduals s = EvaluateStages(model, dofs, options, state, h, state.t + h, true, kRoundOffTolerance,
                                          matrix ? &all : nullptr, threads, work);
  const std::vector<int>& solved = dofs.solved();
  const int n = int(solved.size());
  Eigen::VectorXd residual = Eigen::VectorXd::Constant(3 * n, s.ok ? 0.0 : NAN);
  if (!s.ok) return residual;
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < n; ++k)
      residual[i * n + k] = r.assembly[size_t(i)].residual[solved[size_t(k)]] * RowScale(dofs, solved[size_t(k)], h);
  if (matrix) {
    FactorStageMatrix(dofs, h, r);  // (the sparse form's matrix is assembled by its factorization)
    *matrix = r.J.dense ? r.J.D : Eigen::MatrixXd(r.J.S);
  }
  return residual;
}

// One Radau IIA step of size h from `state` into `next` (above). t_new: the time reached.
StepOutcome RadauStep(const SystemModel& model, const DofMap& dofs, const DynamicOptions& options,
                      const DynamicState& state, double h, double t_new, IterationMatrix& matrix, BodyThreads& threads,
                      BodyWorkspace& work, DynamicState& next) {
  RadauWorkspace& r = work.radau;
  Predict(state, h, r);
  // The residual's round-off floor (RoundOffForce) from the positions' round-off through the
  // stiffness alone: the stage accelerations are unknowns of their own, not differences of the
  // positions as generalized-alpha's are.
  work.inertia_factor = 0.0;
  const double tolerance = std::max(options.tolerance, kRoundOffTolerance);
  const std::vector<int>& solved = dofs.solved();
  const int n = int(solved.size());
  const JacobianReuse reuse = JacobianReuseOf(options);
  if (reuse != JacobianReuse::kSteps || r.factored_h != h) r.factored = false;
  StepOutcome out;
  DivergenceTest divergence;
  double last = -1.0;
  bool refactor = !r.factored;
  // Newton with a kept matrix (the predictor's, while each iteration contracts tenfold) may
  // diverge where one with a fresh matrix at every iteration converges: a large step on a
  // nonlinear model, whose predictor's residual is far from the solution (the slider-crank's rod
  // at 2 ms steps, 1e4-6e4 N). Before the step is cut it starts once more from the predictor so.
  bool fresh_matrices = false, kept_matrix = false;
  for (; out.iterations < options.max_iterations; ++out.iterations) {
    // The matrices with the residuals where they are due before them (the first iterate, full
    // Newton); otherwise decided from the residuals (below), so that a converged iterate builds none.
    refactor = refactor || reuse == JacobianReuse::kNone || fresh_matrices;
    const KeptMatrices kept = KeptMatricesOf(options, reuse, r.factored);
    StageResiduals s = EvaluateStages(model, dofs, options, state, h, t_new, out.iterations == 0, tolerance,
                                      refactor ? &kept : nullptr, threads, work);
    if (!s.ok) return out;
    if (s.small && s.closed && out.iterations > 0) {
      out.converged = true;
      break;
    }
    // Diverging: the caller cuts the step (above: once first from the predictor with fresh
    // matrices). The reference is the first iterate whose loops are closed (DivergenceTest).
    if (divergence.Diverged(s.r_max, s.closed)) {
      if (fresh_matrices || !kept_matrix) return out;
      fresh_matrices = true;
      Predict(state, h, r);
      divergence = DivergenceTest();
      last = -1.0;
      refactor = true;
      continue;
    }
    // Fresh matrices at this iterate when the kept ones' last correction did not contract the
    // residual tenfold (as generalized-alpha's kStep), or when the first left it far from the
    // solution (kFarFromSolution).
    if (!refactor && last >= 0 &&
        (s.r_max > IterationMatrix::kReuseContraction * last ||
         (out.iterations == 1 && LargestScaledResidual(model, dofs, work) > kFarFromSolution * tolerance))) {
      if (!RefreshStageMatrices(model, dofs, options, state, h, t_new, KeptMatricesOf(options, reuse, r.factored),
                                threads, work))
        return out;
      refactor = true;
    }
    kept_matrix = !refactor;
    if (refactor) {
      if (!FactorStageMatrix(dofs, h, r)) {
        out.singular_matrix = std::make_unique<SystemMatrix>(r.assembly[2].K);
        return out;
      }
      r.factored_h = h;
      ++matrix.factorizations;
    }
    refactor = false;
    last = s.r_max;
    r.rhs.resize(3 * n);
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < n; ++k)
        r.rhs[i * n + k] = r.assembly[size_t(i)].residual[solved[size_t(k)]] * RowScale(dofs, solved[size_t(k)], h);
    r.J.Solve(r.rhs, r.correction);
    if (!r.correction.allFinite()) return out;
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < n; ++k) r.A[size_t(i)][solved[size_t(k)]] += r.correction[i * n + k];
  }
  if (!out.converged) return out;
  if (options.adaptive) {
    RadauLocalError(dofs, state, h, r);
    out.error_q = &r.error_q;
    out.error_v = &r.error_v;
  }
  FinishStep(dofs, state, h, t_new, r, next);
  out.passes_kept = true;
  return out;
}

}  // namespace femb::dynamic_internal
