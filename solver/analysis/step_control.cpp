#include "solver/analysis/step_control.h"

#include <algorithm>
#include <cmath>

namespace femb {

StepController::StepController(const SystemModel& model, const DofMap& dofs, const DynamicOptions& options, double t0)
    : options_(options), dofs_(dofs), weights_(ResidualWeights(model, dofs)), x0_(model.node_x0), t0_(t0) {
  const double span = options.end_time - t0;
  min_step_ = options.min_step > 0 ? options.min_step : 1e-8 * span;
  max_step_ = options.max_step > 0 ? options.max_step : 0.01 * span;
  // The model's size (with all nodes at one point the bodies' own: 0 made every error estimate
  // infinite).
  D_ = 1e-3 * ModelSize(model);
  if (options.integrator == Integrator::kMidpoint) {
    c_q_ = 1.0 / 12, c_v_ = 1.0 / 24;
  } else if (options.integrator == Integrator::kRadau) {
    order_ = 5, banded_ = false;
  } else {
    c_q_ = std::abs(AlphaParameters(options.rho_inf).third_order()), c_v_ = 1.0 / 12;
  }
  if (options.integrator == Integrator::kMidpoint && !(options.max_step > 0))
    max_step_ = std::min(max_step_, MidpointResolvedStep(model));
  breakpoints_ = options.breakpoints;
  std::sort(breakpoints_.begin(), breakpoints_.end());
}

double StepController::FirstStep() const { return std::clamp(options_.step, min_step_, max_step_); }

double StepController::Fit(double t, double h) {
  h = std::clamp(h, min_step_, max_step_);
  const double eps = 1e-12 * (options_.end_time - t0_);
  boundary_ = options_.end_time;
  bool breakpoint = false;
  auto after = std::upper_bound(breakpoints_.begin(), breakpoints_.end(), t + eps);
  if (after != breakpoints_.end() && *after < boundary_ - eps) boundary_ = *after, breakpoint = true;
  output_ = true;
  if (options_.output_step > 0) {
    const double k = std::floor((t + eps - t0_) / options_.output_step) + 1;
    const double next_output = t0_ + k * options_.output_step;
    if (next_output < boundary_ - eps) boundary_ = next_output, breakpoint = false;
    output_ = std::abs(next_output - boundary_) <= eps || boundary_ == options_.end_time;
  }
  at_breakpoint_ = breakpoint;
  // The plan: equal steps of at most planned_ to the boundary, made anew at the first step and
  // after a rejection (from the step to retry), and from the proposal when that leaves [0.9, 1.25]
  // of the step in use, at least kSettle steps after the last change or breakpoint, and only
  // where it changes the step. Radau IIA (not banded_) carries nothing across a step that a change
  // disturbs, and takes every proposal that changes the step: the PI controller's growth at a
  // steady error ratio E, 0.9 E^(-0.3/5), stays inside that band down to E = 4e-3.
  const double rest = boundary_ - t;
  const auto equal_steps = [rest](double planned) { return rest / std::max(1.0, std::ceil(rest / planned - 1e-6)); };
  if (proposal_) ++settled_;
  if (!proposal_ || !(kept_ > 0)) {
    planned_ = h;
    settled_ = 0;
  } else if ((!banded_ || ((h < 0.9 * kept_ || h > 1.25 * kept_) && settled_ >= kSettle)) &&
             equal_steps(h) != equal_steps(planned_)) {
    planned_ = h;
    settled_ = 0;
  }
  proposal_ = false;
  const double step = equal_steps(planned_);
  lands_ = step == rest;
  if (!lands_) kept_ = step;
  return step;
}

double MidpointResolvedStep(const SystemModel& model) {
  double omega = 0.0;
  for (const SuperelementBody& body : model.bodies) omega = std::max(omega, HighestFrequency(body));
  return omega > 0.0 ? 0.7 / omega : HUGE_VAL;
}

double StepController::Error(const DynamicState& s0, const DynamicState& s1, double h) {
  const bool midpoint = options_.integrator == Integrator::kMidpoint;
  const double dt_A = midpoint ? 0.5 * (h + s0.h_last) : h;
  if (midpoint) {
    jerk_ = (s1.a - s0.a) / dt_A;  // into jerk_'s storage: no allocation once sized
  } else {
    jerk_ = (s1.Wdot - s0.Wdot) / dt_A;
  }
  const bool with_velocity = has_jerk_prev_ && jerk_prev_.size() == jerk_.size();
  const double h3 = h * h * h, tol_q = options_.step_tolerance * D_;
  double E = 0.0;
  for (int i : dofs_.solved()) {
    E = std::max(E, c_q_ * h3 * std::abs(jerk_[i]) / weights_[i] / tol_q);
    if (with_velocity) {
      const double snap = (jerk_[i] - jerk_prev_[i]) / (0.5 * (h + s0.h_last));
      E = std::max(E, c_v_ * h3 * h * std::abs(snap) / weights_[i] / tol_q);
    }
  }
  return std::isfinite(E) ? E : HUGE_VAL;
}

double StepController::Error(const Eigen::VectorXd& e_q, const Eigen::VectorXd& e_v) {
  const double tol_q = options_.step_tolerance * D_;
  double E = 0.0;
  for (int i : dofs_.solved()) E = std::max({E, std::abs(e_q[i]) / weights_[i], std::abs(e_v[i]) / weights_[i]});
  E /= tol_q;
  return std::isfinite(E) ? E : HUGE_VAL;
}

double StepController::Accept(const DynamicState& s1, double h, double E, bool after_rejection) {
  has_jerk_prev_ = !at_breakpoint();
  if (at_breakpoint()) settled_ = 0;
  if (has_jerk_prev_) jerk_prev_.swap(jerk_);  // jerk_ is written anew by the next Error
  for (size_t k = 0; k < x0_.size(); ++k) D_ = std::max(D_, (s1.config.x[k] - x0_[k]).norm());
  // PI control (Gustafsson 1991; Hairer & Wanner II, IV.2): the exponents 0.7/3 and 0.4/3 of
  // this and the last accepted error ratio damp the step's oscillation that pure
  // E^(-1/3) control shows on the estimate's step-to-step scatter. Measured on the 2D
  // slider-crank (4 bodies): 30% of the steps tried were rejected with E^(-1/3), 2.5% with PI,
  // at the same error per step tried.
  const double f = E_prev_ > 0 && E > 0
                       ? std::clamp(0.9 * std::pow(E, -0.7 / order_) * std::pow(E_prev_, 0.4 / order_), 0.2, 2.0)
                       : Factor(E, order_);
  E_prev_ = std::max(E, 1e-4);
  proposal_ = true;
  return h * std::min(after_rejection ? 1.0 : 2.0, f);
}

double StepController::Factor(double E, double order) {
  if (!(E > 0)) return 2.0;
  return std::clamp(0.9 * (order == 3 ? std::cbrt(1.0 / E) : std::pow(1.0 / E, 1.0 / order)), 0.2, 2.0);
}

}  // namespace femb
