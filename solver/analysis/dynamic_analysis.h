// Dynamic analysis, three integrators on the nodes' coordinates (x_k, R_k) with spatial
// velocities:
// - Lie-group generalized-alpha (Arnold & Bruls 2007, Bruls & Cardona 2010), rotations updated
//   by R <- exp(h dq~) R; Newton with the iteration matrix S = K_t + K_in + gamma' C_t + beta' M_g,
//   K_in = d(M_g wdot)/dq (exact) plus, with full_inertia_tangent, the configuration derivative
//   of the quadratic velocity terms (numerical); numerical damping by rho_inf.
// - Momentum-conserving midpoint (solver/integrators/midpoint.cpp; Simo & Wong 1991 for rigid bodies):
//   the momentum balance over the step at the mid configuration, node rotations advanced by the
//   mean convected angular velocity. Conserves linear and angular momentum exactly for free
//   systems (flexible ones too) and, for rigid bodies, the kinetic energy; no numerical damping.
// - Three-stage Radau IIA (solver/integrators/radau.cpp; Hairer & Wanner IV.5): fifth order,
//   L-stable, on generalized-alpha's residual and matrices; its error-controlled steps take its
//   own local error estimate (an embedded formula, filtered in the stiff directions).
// All cut the step when Newton diverges. Steps are fixed, or error-controlled (`adaptive`):
// the local error of the positions (and what the velocities' error moves them over a step) is
// estimated from the accelerations of the steps taken (step_control.h) and kept below
// step_tolerance of the model's motion; steps land on the kinks and jumps of the loads and
// drives and on output times.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "formats/kinds.h"
#include "solver/assembly/free_solver.h"
#include "solver/assembly/system.h"

namespace femb {

struct DynamicOptions;
JacobianReuse JacobianReuseOf(const DynamicOptions& options);
struct DynamicResume;

struct DynamicOptions {
  /// A stop request, read after each step: when it holds a nonzero value the run stops there,
  /// with what it computed (DynamicResult::stopped). femb-solve points it at the signal number of
  /// a SIGINT or SIGTERM (solver/stop_request.h).
  const std::atomic<int>* stop = nullptr;
  Integrator integrator = Integrator::kGeneralizedAlpha;
  double step = 1e-3;  ///< time step h [time]
  double end_time = 1.0;
  double rho_inf = 0.9;  ///< spectral radius at infinity in [0, 1]; 1: no numerical damping
  int max_iterations = 20;
  double tolerance = 1e-9;  ///< ||residual|| <= tol * (force scale of the step)
  int max_cuts = 8;         ///< halvings of the step before giving up
  /// Which iterations factor the iteration matrix anew (JacobianReuseOf). Unset: kStep with
  /// generalized-alpha, once a step as Adams' pattern T:F:F:F; the residual is exact, so the
  /// converged motion is the same to the Newton tolerance, and a step's later iterations (where
  /// the correction is small) skip the matrices and the factorization, the larger part of an
  /// iteration. kNone with the midpoint scheme: it is chosen for its invariants, which Newton's
  /// last, quadratically converging correction keeps at round-off (modified Newton stops at the
  /// tolerance: a free rigid body's energy to 2.6e-11 at tolerance 1e-12, against 9e-14 with
  /// full Newton, tests/solver/analysis/rigid_body_dynamics_test.cpp).
  std::optional<JacobianReuse> jacobian_reuse;
  /// Generalized-alpha: add the configuration derivative of the quadratic velocity terms to the
  /// iteration matrix (by central differences, 2n inertia evaluations per body). The derivative
  /// of M_g wdot is always in. Measured: 3.57 -> 3.54 iterations per step on a tumbling flexible
  /// body at omega h = 0.04, at ~4x the assembly time; off by default.
  bool full_inertia_tangent = false;
  int reuse_max_iterations = 6;  ///< kSteps: iterations with one factor before a new one
  /// Generalized-alpha with a kept factor (kStep, kSteps): each body's matrices are computed at
  /// the first matrix pass of every `body_matrices_every`-th step and kept in the body's floating
  /// frame; the steps between turn them with the frame, Rbar X Rbar^T (the forces are objective:
  /// turning the body and its motion turns its matrices exactly so), O(n^2) instead of O(n^3).
  /// Within a step a second matrix pass (an iteration that did not contract tenfold) computes
  /// them all. Only Newton's matrix lags: the residual is exact, the motion the same to the
  /// tolerance. Off (1) by default: Newton's last iteration then contracts linearly, so a run
  /// agrees with itself across unit systems or rounding only to the tolerance (a convergence
  /// decision that flips moves it by that much: the SI / mm-t-s pendulum of tests/stress/
  /// numerical_stress_test.cpp 6e-10 of its swing against its 1e-10 bound, one step of 1000
  /// converging one iteration sooner).
  int body_matrices_every = 1;
  /// Which matrices body_matrices_every keeps: kAll (default) the whole body matrix, elastic
  /// tangent with the inertia stiffening and the inertia's configuration tangent included; a kept
  /// step's matrix pass is then three turns and the scatter. kInertia keeps the mass and
  /// gyroscopic matrices alone (the exact inertia's are a body's most expensive kernel) and
  /// computes the tangents every time. The tangents once lagged badly: with the zero-acceleration
  /// predictor, keeping them made Newton wander on a stiff 40-mode pendulum at h = 5 ms
  /// (tests/tools/solve_cli_test.sh's rho_inf 0.5 case); with the constant-acceleration predictor
  /// it takes 1.04 iterations per step either way. What each setting saves on the seed examples
  /// (and the Newton iterations it adds) is measured in the README ("Analyses").
  BodyMatricesKept body_matrices_kept = BodyMatricesKept::kAll;
  /// Error-controlled steps: `step` is the first step; each later one is chosen so that the
  /// estimated local error of the positions (and the velocities' error times the step) stays
  /// below step_tolerance times the largest node travel so far (at least 1e-3 of the model's
  /// size), within [min_step, max_step]. A step below min_step is a failure.
  bool adaptive = false;
  double step_tolerance = 1e-5;
  double min_step = 0.0;            ///< 0: 1e-8 of the analysed time span
  double max_step = 0.0;            ///< 0: 1/100 of the analysed time span
  double output_step = 0.0;         ///< > 0: DynamicStepReport::output marks the steps at its multiples
                                    ///< (adaptive steps land on them; fixed steps: the first at or after)
  std::vector<double> breakpoints;  ///< adaptive steps land on these times (kinks and jumps of loads, drives)
  /// Threads for the bodies' forces and matrices (generalized-alpha; solver/parallel.h). The
  /// results are the same bits for any number.
  int threads = 1;
  /// Continue a run from what DynamicStepReport::capture saved (the state given to SolveDynamic
  /// is then replaced by the saved one): the steps that follow are those of the run it was
  /// saved from, to the bit.
  const DynamicResume* resume = nullptr;
};

inline JacobianReuse JacobianReuseOf(const DynamicOptions& options) {
  if (options.jacobian_reuse) return *options.jacobian_reuse;
  return options.integrator == Integrator::kMidpoint ? JacobianReuse::kNone : JacobianReuse::kStep;
}

struct DynamicState {
  SystemState config;
  Eigen::VectorXd W;     ///< velocities over the unknowns
  Eigen::VectorXd Wdot;  ///< accelerations
  Eigen::VectorXd a;     ///< generalized-alpha acceleration-like variable
  double t = 0.0;
  double external_work = 0.0;
  Eigen::VectorXd f_ext;  ///< external forces (nodal loads, gravity) at t, for the work
  /// Work done by the prescribed motions (the drives): their generalized forces f_drive = -r_p
  /// (the residual on the prescribed coordinates at convergence) times their increments.
  double drive_work = 0.0;
  Eigen::VectorXd f_drive;
  double h_last = 0.0;  ///< the step that reached this state (0 at the start)
  /// Midpoint scheme only: every node's velocity (xdot, omega), carried by the scheme's own
  /// node kinematics rather than taken as J(q) W (see solver/integrators/midpoint.cpp). Empty: J(q) W.
  std::vector<Eigen::Matrix<double, 6, 1>> node_w;
  /// What the integrator carries from its last steps beside the state (saved in checkpoints),
  /// each vector with its step, and how many are kept. Generalized-alpha with error-controlled
  /// steps: the increments Delta q of the last steps (oldest first; none after a breakpoint), for
  /// the velocities' offset at a change of step (solver/integrators/generalized_alpha.cpp). Radau
  /// IIA: the last step's three stage accelerations, for its predictor (solver/integrators/
  /// radau.cpp).
  static constexpr int kIncrements = 3;
  std::array<Eigen::VectorXd, kIncrements> increments;
  std::array<double, kIncrements> increment_steps{};
  int increments_kept = 0;
};

struct DynamicStepReport {
  /// Saves what the run carries into its next step (DynamicResume); valid during on_step.
  const std::function<void(DynamicResume&)>* capture = nullptr;
  /// The run's last step: it reached end_time, or a stop was requested before this report.
  bool last = false;
  double t = 0.0;
  double h = 0.0;
  int iterations = 0;
  long rejected = 0;   ///< steps rejected so far (error test and Newton failures)
  bool output = true;  ///< at an output time (DynamicOptions::output_step)
  double kinetic_energy = 0.0, elastic_energy = 0.0, external_work = 0.0;
  Eigen::Vector3d linear_momentum = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_momentum = Eigen::Vector3d::Zero();
  /// The converged pass's forces on the nodes (residual sense) when that pass is at the reported
  /// state (generalized-alpha: its residual holds at the step's end; not after a breakpoint's
  /// restart, which changes the accelerations), else null: what DynamicReactions would assemble
  /// again. Valid during on_step.
  const NodeForces* node_forces = nullptr;
};

struct DynamicResult {
  bool ok = false;
  std::string message;
  int stopped = 0;  ///< the stop request's value when the run stopped on it (ok, before end_time), else 0
  std::vector<std::string> warnings;  ///< said once each (energy growth below the stop limit)
  long steps = 0;
  long rejected_by_error = 0;                      ///< adaptive steps: tried and rejected by the error test
  long newton_cuts = 0;                            ///< steps cut because Newton diverged
  double smallest_step = 0.0, largest_step = 0.0;  ///< of the steps taken (0 when none)
  double smallest_step_time = 0.0;                 ///< where the smallest one ended
  long newton_iterations = 0;
  long factorizations = 0;          ///< of the iteration matrix
  long pattern_analyses = 0;        ///< of its sparsity pattern (once unless the pattern changes)
  long pivoted = 0;                 ///< factorizations that chose their pivots anew (the others reused them)
  long body_matrices_computed = 0;  ///< bodies' inertia matrices computed (body_matrices_every), all bodies
  long body_matrices_turned = 0;    ///< and turned with their frames instead
};

/// What SolveDynamic carries from one step to the next besides the state: a run resumed from it
/// (DynamicOptions::resume) takes the steps the uninterrupted run takes, to the bit. The pivot
/// order of the iteration matrix's factor is kept (FactorMemory), not the factor: a factor kept
/// across steps (JacobianReuse::kSteps) is computed anew at the first step, so that run continues
/// to the Newton tolerance instead.
struct DynamicResume {
  DynamicState state;
  double t_start = 0.0;  ///< the run's first time (its output times and step limits count from it)
  double h = 0.0;        ///< the next step to try
  double t_base = 0.0, last_output = 0.0, E0 = 0.0, energy_scale = 0.0, first_cut_time = -1.0;
  long n_nominal = 0;
  int cuts = 0;
  bool warned = false;
  /// The result so far: steps, rejections, step sizes, iterations, factorizations, warnings.
  DynamicResult result;
  /// The step controller's memory (step: auto): the largest node travel, the last error ratio,
  /// the last accepted step's jerk.
  double travel = 0.0, last_error = 0.0;
  Eigen::VectorXd last_jerk;
  bool has_last_jerk = false;
  /// ... and its plan: the step planned, the step of equal steps it gave, whether the step to
  /// try is the controller's proposal after an accepted step, the steps since the plan last
  /// changed (StepController::Fit).
  double planned_step = 0.0, kept_step = 0.0;
  bool proposal = false;
  int settled = 0;
  FactorMemory factor;
  long factorizations = 0;
  /// Per body: the inverse frame matrix of its last evaluation (the next frame solve iterates
  /// with it; empty: none), and with body_matrices_every its kept matrices and their age.
  std::vector<Eigen::Matrix<double, 6, 6>> frame_S_inv;
  std::vector<char> has_frame_S_inv;
  std::vector<Eigen::MatrixXd> kept_M, kept_C, kept_K;
  std::vector<int> kept_age;
  long matrices_computed = 0, matrices_turned = 0;
  /// The midpoint scheme's energy closures: per body the derivative and whether it is current
  /// (kept from a step that converged in fewer than 4 iterations).
  std::vector<Eigen::MatrixXd> closure_dc;
  std::vector<char> closure_dc_fresh;
};

/// Initial state: configuration and velocities given; accelerations from M_g wdot = f_ext -
/// f_int - f_gyro at t0. Prescribed coordinates get their rates; if they move and no other
/// coordinate was given a velocity, the others start without deformation rate
/// (K_ff W_f = -K_fp W_p) rather than at rest. With closed loops, given velocities that would
/// open them (G W != 0) are replaced by the nearest that do not, in the kinetic-energy norm.
DynamicState InitialDynamicState(const SystemModel& model, const SystemState& config, const Eigen::VectorXd& W,
                                 double t0 = 0.0);

/// Generalized-alpha's parameters for a spectral radius rho_inf at infinite frequency (Chung and
/// Hulbert 1993, second order with the high frequencies damped most): alpha_m = (2 rho - 1) /
/// (rho + 1), alpha_f = rho / (rho + 1), gamma = 1/2 + alpha_f - alpha_m, beta = (gamma + 1/2)^2
/// / 4; rho_inf clamped to [0, 1].
struct AlphaParameters {
  double alpha_m, alpha_f, gamma, beta;
  explicit AlphaParameters(double rho_inf) {
    const double rho = std::clamp(rho_inf, 0.0, 1.0);
    alpha_m = (2 * rho - 1) / (rho + 1);
    alpha_f = rho / (rho + 1);
    gamma = 0.5 + alpha_f - alpha_m;
    beta = 0.25 * (gamma + 0.5) * (gamma + 0.5);
  }
  /// The constant of the positions' local error, q(t_n+1) - q_n+1 = c h^3 q''' + O(h^4):
  /// 1/6 - beta - (alpha_m - alpha_f) / 2 (the step controller's estimate and the velocity
  /// offset moved at a change of step).
  double third_order() const { return 1.0 / 6 - beta - 0.5 * (alpha_m - alpha_f); }
};

/// A body's highest natural frequency [rad/s] of its reduced K and M (free-free, in its
/// interface coordinates); 0 for a rigid body.
double HighestFrequency(const SuperelementBody& body);

/// Energies and momenta of a state.
DynamicStepReport Measure(const SystemModel& model, DynamicState& state);

/// The state with its accelerations and multipliers from its positions and velocities: the
/// equations of motion with the constraints' second time derivative, [M G^T; G 0] [Wdot; lambda]
/// = [f; -Gdot W] (index 1). What reactions are computed from. An integrator's own ones differ:
/// index-3 generalized-alpha satisfies the constraints on the positions, and its accelerations
/// and multipliers carry an oscillation of period 2 steps, excited by every change of the step
/// and damped only by rho_inf (measured: 4% of the peak reaction of a four-bar with a flexible
/// coupler whose error-controlled steps change by 5-10% a step); the midpoint scheme's are
/// extrapolated from its mean accelerations (O(h)). Without loops, generalized-alpha's
/// accelerations already satisfy the equations of motion at t_n+1 and the state is returned
/// as it is.
DynamicState WithConsistentAccelerations(const SystemModel& model, const DynamicState& state);
/// Whether the state's accelerations and multipliers are the consistent ones as they are (no
/// closed loops, not the midpoint scheme's): WithConsistentAccelerations returns it unchanged.
bool AccelerationsConsistent(const SystemModel& model, const DynamicState& state);

/// Support and joint reactions (JointReactions, solver/joints/joint_tree.h) at a state: the inertia forces with its
/// accelerations (give it WithConsistentAccelerations' state).
std::vector<Eigen::Matrix<double, 6, 1>> DynamicReactions(const SystemModel& model, const DynamicState& state);

/// Integrates from state.t to options.end_time; `on_step` after every converged step.
DynamicResult SolveDynamic(const SystemModel& model, DynamicState& state, const DynamicOptions& options,
                           const std::function<void(const DynamicStepReport&, const DynamicState&)>& on_step = nullptr);

}  // namespace femb
