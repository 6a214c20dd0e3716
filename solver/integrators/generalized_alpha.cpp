// The generalized-alpha integrator (Chung & Hulbert 1993 on the Lie group of the nodes, Arnold &
// Bruls 2007; index 3 with closed loops): its step, and the dynamic residual and iteration
// matrix it assembles (shared with the consistent start and the reactions).
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <functional>

#include "solver/analysis/dynamic_step.h"
#include "solver/body/body_blocks.h"
#include "solver/rotation.h"

namespace femb::dynamic_internal {

void AssembleDynamicResidual(const SystemModel& model, const DofMap& dofs, DynamicState& s, double t,
                             BodyWorkspace& work, BodyThreads* threads, Assembly& out) {
  AssemblyParts& parts = work.parts;
  StartAssembly(model, dofs, parts, out);
  const int n_bodies = int(model.bodies.size());
  std::vector<BodyPass>& passes = work.passes;
  std::vector<BodyTerms>& results = work.terms;
  passes.resize(static_cast<size_t>(n_bodies));
  results.resize(static_cast<size_t>(n_bodies));
  work.pass_data.resize(size_t(n_bodies));
  for (int b = 0; b < n_bodies; ++b) work.pass_data[size_t(b)] = &passes[size_t(b)].data;
  NodeAccelerations(model, dofs, s.config, s.W, s.Wdot, work.node_acc, &work.parts.scratch);
  const std::vector<Eigen::Matrix<double, 6, 1>>& node_acc = work.node_acc;
  BodyPassKind kind;
  kind.warm_frame = true;
  kind.inertia_factor = work.inertia_factor;
  kind.gravity = model.gravity;
  ForEachBody(threads, n_bodies, [&](int b) {
    BodyPass& pass = passes[size_t(b)];
    GatherBody(model, dofs, s.config, b, s.W, pass.w);
    GatherBodyAcceleration(model, dofs, b, node_acc, s.Wdot, pass.wdot);
    EvaluateBodyTerms(model, dofs, s.config, b, kind, pass, results[size_t(b)]);
  });
  if (!AddBodyTerms(model, results, parts, out)) return;
  FinishAssembly(model, dofs, s.config, t, s.W, false, parts, out);
  AddLoopConstraints(model, dofs, s.config, &out.residual, nullptr, &out.node_forces, nullptr, kLoopAll,
                     &work.pass_data, &work.parts.scratch);
}

Assembly AssembleDynamicResidual(const SystemModel& model, const DofMap& dofs, DynamicState& s, double t,
                                 BodyWorkspace& work, BodyThreads* threads) {
  Assembly out;
  AssembleDynamicResidual(model, dofs, s, t, work, threads, out);
  return out;
}

namespace {

// Which bodies turn their kept matrices in this pass (BodyMatricesKept, `every`), decided in body
// order: the same for any number of threads. Counts them into work.
void DecideKeptMatrices(const SystemModel& model, int every, bool all_kept, BodyWorkspace& work) {
  const int n_bodies = int(model.bodies.size());
  std::vector<BodyWorkspace::BodyMatrices>& results = work.matrices;
  for (int b = 0; b < n_bodies; ++b) {
    BodyWorkspace::BodyMatrices& r = results[size_t(b)];
    const int n = model.bodies[b].n_coordinates();
    const bool kept =
        every > 1 && r.age >= 0 && r.age < every - 1 && r.M_frame.rows() == n && (!all_kept || r.K_frame.rows() == n);
    r.age = kept ? r.age + 1 : (every > 1 || r.age >= 0 ? 0 : -1);  // a pass that computes keeps them anew
    ++(kept ? work.matrices_turned : work.matrices_computed);
  }
}

// One body's K, C and M of the dynamic residual at its pass (computed, or kept and turned with the
// frame), into r; with `combine` K + c_C C + c_M M into r.K.
void BodyDynamicMatrices(const SuperelementBody& body, BodyPass& pass, const Eigen::Vector3d& gravity,
                         bool full_inertia_tangent, const MatrixCombination* combine, bool all_kept,
                         BodyWorkspace::BodyMatrices& r) {
  const bool stiffening = body.has_inertia_stiffening();
  const int blocks = 2 * body.n_nodes();
  const Eigen::Matrix3d& R = pass.data.frame.R;
  const Eigen::Matrix3d Rt = R.transpose();
  // to <- Rbar from Rbar^T, Rbar = blockdiag(Q, ..., Q, 1) (storage reused: the same size at every pass)
  const auto turned = [blocks](Eigen::MatrixXd& to, const Eigen::MatrixXd& from, const Eigen::Matrix3d& Q) {
    to = from;
    body_blocks::TurnNodeBlocks(to, blocks, Q);
  };
  if (all_kept && r.age > 0) {
    // All of the body's matrices kept (BodyMatricesKept::kAll): turned with the frame.
    turned(r.K, r.K_frame, R);
    turned(r.C, r.C_frame, R);
    turned(r.M, r.M_frame, R);
    if (combine) r.K += combine->c_C * r.C + combine->c_M * r.M;
    return;
  }
  Eigen::MatrixXd& d_load = r.d_load;
  ElasticForce(body, pass.data, nullptr, &r.K, stiffening ? &pass.load : nullptr, stiffening ? &d_load : nullptr);
  // The inertia force's mass and gyroscopic matrices (the exact inertia's are a body's most
  // expensive kernel): computed, or the kept ones turned. The inertia force is objective:
  // turning the whole body and its motion by Q turns every node block of the two matrices,
  // X -> Q X Q^T (tests/solver/analysis/body_matrix_reuse_test.cpp). So X_frame = Rbar^T X Rbar
  // changes only with the deformation and the velocities in the frame, and Rbar X_frame Rbar^T
  // is the matrix of this pass but for their change since. With kInertia the elastic tangent
  // and the inertia's configuration tangent are computed every time: they carry the internal
  // forces (K2, K3, stiffening) and the accelerations. With kAll they are kept and turned too
  // (above): the internal forces and accelerations are objective as well, so the kept matrix
  // lags by their change in the frame, as the inertia's does.
  if (!all_kept && r.age > 0) {
    turned(r.M, r.M_frame, R);
    turned(r.C, r.C_frame, R);
  } else {
    InertiaForce(body, pass.data, pass.w, pass.wdot, nullptr, &r.M, &r.C);
    if (!all_kept && r.age == 0) {
      turned(r.M_frame, r.M, Rt);
      turned(r.C_frame, r.C, Rt);
    }
  }
  if (stiffening) {
    r.M.noalias() += d_load * pass.load.d_wdot;
    r.C.noalias() += d_load * pass.load.d_w;
  }
  // Configuration derivative of the inertia force less the weight: d(M_g wdot)/dq exactly; that
  // of the quadratic velocity terms by central differences with options.full_inertia_tangent.
  // The weight is the inertia force's acceleration part at the uniform field g (GravityForce =
  // f_acc(wdot_g), wdot_g = g on the node translations, for the corotational and the exact
  // inertia alike), so f_in - f_grav = f_in(w, wdot - wdot_g) and one call takes both.
  if (gravity.squaredNorm() > 0) {
    r.wdot = pass.wdot;
    for (int a = 0; a < body.n_nodes(); ++a) r.wdot.segment<3>(6 * a) -= gravity;
    InertiaConfigurationTangent(body, pass.data, pass.w, r.wdot, full_inertia_tangent, r.inertia_K);
  } else {
    InertiaConfigurationTangent(body, pass.data, pass.w, pass.wdot, full_inertia_tangent, r.inertia_K);
  }
  r.K += r.inertia_K;
  r.unused.setZero(body.n_coordinates());
  AddModalDamping(body, pass.w, r.unused, &r.C);
  if (all_kept && r.age == 0) {
    turned(r.K_frame, r.K, Rt);
    turned(r.C_frame, r.C, Rt);
    turned(r.M_frame, r.M, Rt);
  }
  if (combine) r.K += combine->c_C * r.C + combine->c_M * r.M;
}

}  // namespace

void AddDynamicMatrices(const SystemModel& model, const DofMap& dofs, const DynamicState& s, double t,
                        BodyWorkspace& work, bool full_inertia_tangent, Assembly& out, BodyThreads* threads,
                        const MatrixCombination* combine, int every, BodyMatricesKept which) {
  const int n_bodies = int(model.bodies.size());
  std::vector<BodyPass>& passes = work.passes;
  std::vector<BodyWorkspace::BodyMatrices>& results = work.matrices;
  results.resize(static_cast<size_t>(n_bodies));
  const bool all_kept = which == BodyMatricesKept::kAll;
  DecideKeptMatrices(model, every, all_kept, work);
  ForEachBody(threads, n_bodies, [&](int b) {
    BodyDynamicMatrices(model.bodies[b], passes[size_t(b)], model.gravity, full_inertia_tangent, combine, all_kept,
                        results[size_t(b)]);
  });
  Triplets &K = work.K, &C = work.C, &M = work.M;
  K.clear();
  C.clear();
  M.clear();
  // The joints' convective accelerations depend on W: d f_in / dW gets M_b dc/dW (the Coriolis
  // and centripetal coupling of chains with offsets), into C (or c_C of it into K).
  // And their configuration: d f_in / dq gets M_b d(J Wdot + c)/dq (into K).
  // Supports (joints to the ground with constant maps) have no such terms.
  const bool chains =
      std::any_of(model.joints.begin(), model.joints.end(), [](const NodeJoint& j) { return !ConstantMaps(j); });
  if (chains) {
    ConvectiveVelocityDerivative(model, dofs, s.config, s.W, work.dc);
    NodeAccelerationConfigurationDerivative(model, dofs, s.config, s.W, s.Wdot, work.dacc, &work.parts.scratch);
  }
  const std::vector<NodeJacobian>& dc = work.dc;
  const std::vector<NodeJacobian>& dacc = work.dacc;
  // B^T M_b D for a body's node columns D (per node, sparse over the coordinates), scaled.
  Eigen::VectorXd& y = work.column;
  const auto add_node_columns = [&](const std::vector<MapEntry>& map, const Eigen::MatrixXd& M_b, int b,
                                    const std::vector<NodeJacobian>& D, double scale, Triplets& into) {
    for (size_t a = 0; a < model.body_nodes[size_t(b)].size(); ++a) {
      for (const auto& [col, v] : D[size_t(model.body_nodes[size_t(b)][a])]) {
        y.resize(M_b.rows());
        y.noalias() = M_b.middleCols<6>(Eigen::Index(6 * a)) * v;
        for (const MapEntry& e : map) {
          const double value = e.coefficient * y[e.local];
          if (value != 0.0) into.emplace_back(e.coordinate, col, scale * value);
        }
      }
    }
  };
  for (int b = 0; b < n_bodies; ++b) {
    const BodyWorkspace::BodyMatrices& r = results[size_t(b)];
    const std::vector<MapEntry>& map = work.terms[size_t(b)].map;  // the residual pass's, same state
    ScatterBody(map, nullptr, &r.K, nullptr, &K);
    if (chains) {
      // r.M: d f_in / d wdot of the body (the combination above went into r.K only).
      add_node_columns(map, r.M, b, dacc, 1.0, K);
      if (combine) {
        add_node_columns(map, r.M, b, dc, combine->c_C, K);
      } else {
        add_node_columns(map, r.M, b, dc, 1.0, C);
      }
    }
    if (combine) continue;
    ScatterBody(map, nullptr, &r.C, nullptr, &C);
    ScatterBody(map, nullptr, &r.M, nullptr, &M);
  }
  const int n = dofs.n_dofs();
  Eigen::VectorXd& unused = work.unused;
  unused.setZero(n);
  AddNodeLoads(model, s.config, t, unused, &K);
  AddUserForces(model, s.config, s.W, t, nullptr, &K, &C, nullptr);
  AddSpringDampers(model, s.config, s.W, nullptr, &K, &C, nullptr, nullptr, &work.parts.scratch);
  AddLoopConstraints(model, dofs, s.config, nullptr, &K, nullptr, nullptr, kLoopAll, &work.pass_data,
                     &work.parts.scratch);
  AddJointGeometricStiffness(model, dofs, s.config, out.node_forces, K, &work.parts.scratch);
  if (combine) {
    for (const Eigen::Triplet<double>& e : C) K.emplace_back(e.row(), e.col(), combine->c_C * e.value());
    out.K = work.K_build.Build(n, K);
    return;
  }
  out.K = work.K_build.Build(n, K);
  out.C = work.C_build.Build(n, C);
  out.M = work.M_build.Build(n, M);
}

Assembly AssembleDynamic(const SystemModel& model, const DofMap& dofs, DynamicState& s, double t, bool matrices,
                         bool full_inertia_tangent) {
  BodyWorkspace work;
  Assembly out = AssembleDynamicResidual(model, dofs, s, t, work);
  if (out.ok && matrices) AddDynamicMatrices(model, dofs, s, t, work, full_inertia_tangent, out);
  return out;
}

namespace {

// The velocities' share of a change of step size from h_n (the last step) to h, beside a_n's
// (below). Generalized-alpha carries a velocity that is the motion's own up to c_v h_n^2 q3 (q3
// the motion's third derivative, c_v = 1/6 - beta - (alpha_m - alpha_f) / 2: with that offset the
// position update is exact for a cubic motion, as it is with a_n's (alpha_m - alpha_f) h_n q3).
// In the directions that stiff elastic forces hold (the static modes of a flexible body) and in
// the loops' constrained ones, the step balances the offset through the positions: kept at h_n^2
// after a change of step, it sets their forces off, and the jolt rings in the bodies' resolved
// modes. The tilted four-bar with a flexible coupler (tests/solver/analysis/
// dynamic_consistency_test.cpp): one doubling of a steady 0.5 ms step put the ground reactions
// 8.4e-3 of their peak off for the rest of the run, where the steady steps kept them within
// 1e-4. The offset is moved to c_v h^2 q3 with q3 from the third divided difference of the last
// three steps' increments: positions, since the accelerations and velocities of stiff directions
// are no estimate of it (a correction from them grew without bound on random step sequences).
// Error-controlled steps only, where the steps resolve the motion and change seldom
// (StepController::Fit); a fixed step changes only where Newton cut it, where q3 from steps too
// long for the motion is no estimate (a pendulum at 0.5 s steps diverged with it). Into `W`
// (holding W_n); nothing without three steps kept since the start or the last breakpoint.
void MoveVelocityOffset(const DofMap& dofs, const DynamicState& s, double h, double c_v, BodyWorkspace& work,
                        Eigen::VectorXd& W) {
  if (s.increments_kept < 3 || s.h_last <= 0 || h == s.h_last) return;
  const auto& d = s.increments;
  const auto& hs = s.increment_steps;  // oldest first; hs[2] = h_last
  const double f = 6 * c_v * (h * h - s.h_last * s.h_last) / (hs[0] + hs[1] + hs[2]);
  Eigen::VectorXd& dv = work.velocity_change;
  dv.setZero(dofs.n_dofs());
  for (int i : dofs.solved()) {
    if (dofs.multiplier(i)) continue;
    const double d0 = d[0][i] / hs[0], d1 = d[1][i] / hs[1], d2 = d[2][i] / hs[2];
    dv[i] = f * ((d2 - d1) / (hs[1] + hs[2]) - (d1 - d0) / (hs[0] + hs[1]));
  }
  W += dv;
}

// The converged step's increment Delta q kept for MoveVelocityOffset (newest last; all sized on
// the first step, so that no later step allocates).
void KeepIncrement(const DynamicState& state, double h, const Eigen::VectorXd& dq, DynamicState& next) {
  constexpr int N = DynamicState::kIncrements;
  for (Eigen::VectorXd& v : next.increments)
    if (v.size() != dq.size()) v.setZero(dq.size());
  for (int k = 0; k + 1 < N; ++k) {
    next.increments[size_t(k)].swap(next.increments[size_t(k + 1)]);
    next.increment_steps[size_t(k)] = state.increment_steps[size_t(k + 1)];
  }
  next.increments[N - 1] = dq;
  next.increment_steps[N - 1] = h;
  next.increments_kept = std::min(state.increments_kept + 1, N);
}

}  // namespace

// One generalized-alpha step of size h from `state` into `next` (Arnold & Bruls 2007).
// t_new: the time reached, state.t + h, or just below a breakpoint the step lands on (the loads
// and drives there are their left limits).
StepOutcome GeneralizedAlphaStep(const SystemModel& model, const DofMap& dofs, const DynamicOptions& options,
                                 const DynamicState& state, double h, double t_new, IterationMatrix& matrix,
                                 BodyThreads& threads, BodyWorkspace& work, DynamicState& next) {
  const AlphaParameters alpha(options.rho_inf);
  const double alpha_m = alpha.alpha_m, alpha_f = alpha.alpha_f, gamma = alpha.gamma, beta = alpha.beta;
  next = state;  // storage reused: `next` is the caller's, of the same sizes after the first step
  // Predictor: constant acceleration, Wdot_n+1 = Wdot_n, and a_n+1 from (1 - alpha_m) a_n+1 +
  // alpha_m a_n = (1 - alpha_f) Wdot_n+1 + alpha_f Wdot_n. Arnold & Bruls predict Wdot_n+1 = 0,
  // which for a smooth motion misses the step's position by about beta h^2 (1 - (alpha_f -
  // alpha_m) / (1 - alpha_m)) Wdot: five sixths of the acceleration's share at rho_inf = 0.8.
  // Constant acceleration misses it by O(h^3); measured on the peer slider-crank (2 stiffened
  // rod bodies, h = 150 us, tolerance 1e-4): 1.79 -> 1.17 Newton iterations per step. The
  // converged state does not depend on the predictor (to the tolerance) since the configuration
  // is q_n o exp(Delta q) below.
  //
  // The acceleration-like a_n stands for Wdot at t_n + (alpha_m - alpha_f) h_n, a time that moves
  // with the step (a_n - Wdot_n = (alpha_m - alpha_f) h_n Wdot' + O(h^2)). A step of another
  // size takes it there by a_n* = Wdot_n + (h / h_n) (a_n - Wdot_n): kept as it was, it is off by
  // O(h - h_n), which the constrained directions (index-3 loops, where the positions are fixed
  // by the constraints) answer with an oscillation of the accelerations and multipliers: spikes
  // in the reactions after every change of step of error-controlled runs.
  Eigen::VectorXd& a_n = work.a_n;
  a_n = state.a;
  if (state.h_last > 0 && h != state.h_last) a_n = state.Wdot + (h / state.h_last) * (state.a - state.Wdot);
  Eigen::VectorXd& W_n = work.W_n;
  W_n = state.W;
  work.velocity_change.resize(dofs.n_dofs());  // sized on the first step: it is needed at a change of step
  if (options.adaptive) MoveVelocityOffset(dofs, state, h, alpha.third_order(), work, W_n);
  next.a = (state.Wdot - alpha_m * a_n) / (1 - alpha_m);
  next.W = W_n + h * (1 - gamma) * a_n + h * gamma * next.a;
  work.dq = h * (W_n + h * (0.5 - beta) * a_n + h * beta * next.a);
  ApplyIncrement(model, dofs, work.dq, next.config);
  ApplyPrescribed(model, dofs, t_new, next.config, &next.W, &next.Wdot, &work.parts.scratch);
  const double gamma_p = gamma / (beta * h), beta_p = (1 - alpha_m) / (beta * h * h * (1 - alpha_f));
  work.inertia_factor = beta_p;
  StepOutcome out;
  const double tolerance = std::max(options.tolerance, kRoundOffTolerance);
  const Eigen::VectorXd& weights = work.Weights(model, dofs);
  DivergenceTest divergence;
  Assembly& a = work.assembly;
  matrix.BeginStep();
  for (; out.iterations < options.max_iterations; ++out.iterations) {
    AssembleDynamicResidual(model, dofs, next, t_new, work, &threads, a);
    if (!a.ok || !a.residual.allFinite()) return out;
    const double r_norm = FreeNorm(dofs, a.residual, weights);
    // Converged: the residual below the tolerance relative to the forces on each unknown (or
    // at the round-off of the positions), after at least one correction.
    if (ResidualSmall(dofs, a, weights, r_norm, tolerance) && out.iterations > 0 &&
        LoopsClosed(model, next.config, tolerance, &work.pass_data, &work.parts.scratch)) {
      out.converged = true;
      next.a =
          (alpha_f * state.Wdot + (1 - alpha_f) * next.Wdot - alpha_m * a_n) / (1 - alpha_m);  // (the same relation)
      if (options.adaptive) KeepIncrement(state, h, work.dq, next);
      next.t = t_new;
      // External work by the trapezoidal rule on the increment h (W_n + W_n+1) / 2.
      next.external_work += 0.5 * (state.f_ext + a.f_ext).dot(h * 0.5 * (state.W + next.W));
      next.f_ext = a.f_ext;
      DriveForces(dofs, a.residual, next.f_drive);
      next.drive_work += 0.5 * (state.f_drive + next.f_drive).dot(h * 0.5 * (state.W + next.W));
      out.passes_kept = true;
      return out;
    }
    if (divergence.Diverged(r_norm, !model.has_constraints() || LoopsClosed(model, next.config, tolerance,
                                                                            &work.pass_data, &work.parts.scratch))) {
      return out;
    }
    bool built = false;
    const auto S = [&]() -> const SystemMatrix& {
      const MatrixCombination combine{gamma_p, beta_p};
      // The step's first matrix may take the bodies' kept inertia matrices (body_matrices_every);
      // a second one (the first did not contract tenfold) and full Newton compute them all.
      const int every = JacobianReuseOf(options) != JacobianReuse::kNone && !matrix.factored_in_step
                            ? std::max(options.body_matrices_every, 1)
                            : 1;
      if (!built)
        AddDynamicMatrices(model, dofs, next, t_new, work, options.full_inertia_tangent, a, &threads, &combine, every,
                           options.body_matrices_kept);
      built = true;
      return a.K;  // K + gamma' C + beta' M
    };
    Eigen::VectorXd& delta = work.delta;
    if (!matrix.Increment(dofs, options, h, r_norm, S, a.residual, delta, out.singular_matrix)) return out;
    // The step's increment Delta q (work.dq) takes Newton's correction, and the configuration
    // is q_n+1 = q_n o exp(Delta q) (the Lie group generalized-alpha of Bruls, Cardona & Arnold 2012):
    // on a rotation triple R_n+1 = exp(Delta q~) R_n, reached from the current R_n+1 by
    // log(exp(Delta q~) R_n R_n+1^T), not by composing the corrections, exp(delta~) R_n+1, which
    // would make the converged state depend on the path Newton took (the predictor) by the
    // corrections' commutators. Every other unknown adds.
    work.dq += delta;
    Eigen::VectorXd& lie_delta = work.lie_delta;
    lie_delta = delta;
    for (const RotationNode& n : work.rotation_triples) {
      const Eigen::Matrix3d target =
          ExpSO3(Eigen::Vector3d(work.dq.segment<3>(n.rotation))) * state.config.R[size_t(n.node)];
      lie_delta.segment<3>(n.rotation) = LogSO3(Eigen::Matrix3d(target * next.config.R[size_t(n.node)].transpose()));
    }
    ApplyIncrement(model, dofs, lie_delta, next.config);
    next.W += gamma_p * delta;
    next.Wdot += beta_p * delta;
    dofs.ClearMultipliers(next.W);  // the multipliers took their increment in next.config
    dofs.ClearMultipliers(next.Wdot);
  }
  return out;
}

}  // namespace femb::dynamic_internal
