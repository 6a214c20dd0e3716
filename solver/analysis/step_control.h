// Error-controlled time steps for SolveDynamic (DynamicOptions::adaptive): the local error
// estimate, the step it allows, and where steps must land.
//
// Local error estimate from the accelerations of the steps taken (Zienkiewicz & Xie 1991 for
// Newmark's method, here for both integrators): a jerk estimate per coordinate,
//   j_n+1 = (A_n+1 - A_n) / dt_A
// with A the accelerations (generalized-alpha: Wdot at t_n and t_n+1, dt_A = h; midpoint: the
// mean acceleration of each step, at t_n+1/2 and t_n-1/2, dt_A = (h + h_last) / 2), gives the
// local error of the positions over a step of h
//   e_q = C_q h^3 j,   C_q = 1/6 - beta - (alpha_m - alpha_f) / 2 (generalized-alpha), 1/12 (midpoint).
// Generalized-alpha: q_n+1 = q_n + h W_n + h^2 ((1/2 - beta) a_n + beta a_n+1) with the
// acceleration-like a_n = Wdot(t_n + (alpha_m - alpha_f) h) + O(h^2) (from (1 - alpha_m) a_n+1 +
// alpha_m a_n = (1 - alpha_f) Wdot_n+1 + alpha_f Wdot_n); Taylor's expansion of q(t_n + h) leaves
// C_q h^3 q'''. rho_inf = 1 gives -1/12, the trapezoidal rule's constant, which is also the
// midpoint scheme's (its positions advance by h (W_n + W_n+1) / 2). Velocities are second order
// (gamma = 1/2 + alpha_f - alpha_m): their local error is third order too, estimated from the
// change of the jerk,
//   e_v = C_v h^3 (j_n+1 - j_n) / ((h + h_last) / 2),   C_v = 1/12 (trapezoidal), 1/24 (midpoint rule).
// The estimates are compared coordinate by coordinate as lengths (e_i / w_i, w the residual
// weights: rotations times the model's size, modal coordinates over sqrt(mass)) with
//   step_tolerance * D,
// D the largest node travel so far (at least 1e-3 of the model's size): a relative error of the
// motion, so a cantilever that deflects a millimetre is judged against that millimetre, a crank
// against its stroke. The velocity error enters as what it moves the positions over the next
// step, h e_v. Judged against a velocity scale of its own (the largest velocity so far), the
// velocity estimate, a second difference of the accelerations, follows the high modes that the
// integrator is meant to damp: the rotating beam (seed 5.4, 10 bodies) took 51 018 steps at a
// tolerance of 1e-3 instead of 576 with positions only, for an error of 0.36% where 8 047 steps
// give 0.27% this way (benchmarks/step_control.py). The largest ratio E decides: E <= 1 accepts;
// the next step follows by PI control (Accept; the error goes with h^3; no growth right after a
// rejection, a rejected step is retried at h clamp(0.9 E^(-1/3), 0.2, 1)). Prescribed
// coordinates are exact and not judged.
// Steps land on breakpoints (kinks and jumps of loads and drives), so a jump never falls inside a
// step; the jerk history restarts after one.
//
// Where steps land (Fit): each stretch to the next boundary (output time, breakpoint, end) is
// taken in equal steps of at most the planned step. The plan is made at the first step and after
// a rejection (from the step to retry); otherwise it changes only when the controller's proposal
// after an accepted step leaves [0.9, 1.25] of the step in use, at least 7 steps after the last
// change or breakpoint, and only when that moves the step. Why the step changes seldom: every
// change sets generalized-alpha's stiff directions (the static modes of a flexible body, the
// loops' constrained directions) off by its velocities' offset, which the integrator moves at the
// change (generalized_alpha.cpp) from an estimate of the motion's third derivative; that move
// excites the stiff directions a little in turn, and the jerk estimate sees it. Changed at every
// step, the steps collapse (rotating_beam, 10 bodies: 57 649 steps against 2 716 at a tolerance
// of 1e-4); without the settling too (cantilever_transient at 1e-5: 67 000 against 3 361); a
// band of [0.7, 1.25] lets the error double at loose tolerances. benchmarks/step_control.py
// measures the steps and errors of every dynamic example (docs/performance.md).
//
// Radau IIA estimates its own local error (solver/integrators/radau.cpp, RadauLocalError), of
// order h^5: the controller takes it as it is, with the exponents of h^5 (1/5 where the others
// take 1/3), and the plan follows every proposal that changes the step (a one-step scheme: a
// change disturbs nothing it carries; and at a steady ratio E the PI growth 0.9 E^(-0.3/5) stays
// inside [0.9, 1.25] down to E = 4e-3, which held a free rigid body's steps at 1/160 of the error
// allowed).
//
// The midpoint scheme damps no mode, so its reactions and stresses carry every excited mode that
// its steps do not resolve, whatever the motion's error: its steps stay at or below 0.7 / omega
// of the bodies' highest reduced-model frequency unless max_step is given (MidpointResolvedStep).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "solver/analysis/dynamic_analysis.h"

namespace femb {

/// The midpoint scheme's largest step under error control: 0.7 / omega of the bodies' highest
/// reduced-model frequency (omega: the largest of sqrt(eig(K, M)) over the flexible bodies);
/// HUGE_VAL without flexible bodies. Measured on the tilted four-bar with a flexible coupler
/// (11.7 kHz) against its own fixed 5 us run: ground reactions within 1.4e-3 of their peak at
/// omega h <= 1, 6e-4 at 0.7, 0.12-1.5 times the peak with the motion's error alone.
double MidpointResolvedStep(const SystemModel& model);

class StepController {
 public:
  /// For a run from t0 to options.end_time (options and dofs must outlive the controller).
  StepController(const SystemModel& model, const DofMap& dofs, const DynamicOptions& options, double t0);
  double min_step() const { return min_step_; }
  double max_step() const { return max_step_; }
  /// options.step within [min_step, max_step].
  double FirstStep() const;

  /// The step to try from t: of equal steps to the next boundary (end time, breakpoint, output
  /// time), the planned one, within [min_step, max_step]; h is the controller's proposal (after
  /// Accept), the step to retry (after a rejection) or the first step.
  double Fit(double t, double h);
  /// After Fit: whether the step lands on the boundary, which one, and what it is.
  bool lands() const { return lands_; }
  double boundary() const { return boundary_; }
  bool at_breakpoint() const { return lands_ && at_breakpoint_; }
  bool output() const { return lands_ && output_; }

  /// The error ratio E of the step of h from s0 to s1 (<= 1: accept); keeps the jerk for Accept.
  double Error(const DynamicState& s0, const DynamicState& s1, double h);
  /// The error ratio E of a step whose integrator estimated its own local error (Radau IIA):
  /// e_q of the positions, e_v of the velocities times the step, over the coordinates.
  double Error(const Eigen::VectorXd& e_q, const Eigen::VectorXd& e_v);
  /// The next step after an accepted one with error ratio E; updates the motion scale.
  double Accept(const DynamicState& s1, double h, double E, bool after_rejection);
  /// The factor for a step retried after a rejection with error ratio E (or with no history),
  /// for an estimate that goes with h^order.
  static double Factor(double E, double order = 3);
  /// Factor with this run's estimate's power of the step.
  double RetryFactor(double E) const { return Factor(E, order_); }
  /// What Accept keeps for the next steps, into or from a DynamicResume.
  void Save(DynamicResume& r) const {
    r.travel = D_, r.last_error = E_prev_, r.last_jerk = jerk_prev_, r.has_last_jerk = has_jerk_prev_;
    r.planned_step = planned_, r.kept_step = kept_, r.proposal = proposal_, r.settled = settled_;
  }
  void Restore(const DynamicResume& r) {
    D_ = r.travel, E_prev_ = r.last_error, jerk_prev_ = r.last_jerk, has_jerk_prev_ = r.has_last_jerk;
    planned_ = r.planned_step, kept_ = r.kept_step, proposal_ = r.proposal, settled_ = r.settled;
  }

 private:
  const DynamicOptions& options_;
  const DofMap& dofs_;
  Eigen::VectorXd weights_, jerk_, jerk_prev_;
  bool has_jerk_prev_ = false;  ///< jerk_prev_ holds the last accepted step's (none after a breakpoint)
  std::vector<Eigen::Vector3d> x0_;
  double t0_ = 0;
  std::vector<double> breakpoints_;
  double planned_ = 0, kept_ = 0;  ///< the planned step, and the equal steps it gave (Fit)
  bool proposal_ = false;          ///< Fit's h is the controller's proposal after an accepted step
  int settled_ = 0;                ///< accepted steps since the last change of plan or breakpoint
  static constexpr int kSettle = 7;
  double min_step_ = 0, max_step_ = 0, D_ = 0, c_q_ = 0, c_v_ = 0, boundary_ = 0, E_prev_ = 0;
  double order_ = 3;    ///< the estimate's power of the step: h^3, or h^5 for Radau IIA's
  bool banded_ = true;  ///< the plan changes only outside [0.9, 1.25] after kSettle steps (Fit)
  bool lands_ = false, output_ = true, at_breakpoint_ = false;
};

}  // namespace femb
