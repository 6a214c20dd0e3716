#include "solver/analysis/dynamic_analysis.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>

#include "solver/analysis/dynamic_step.h"
#include "solver/analysis/singularity.h"
#include "solver/analysis/step_control.h"
#include "solver/parallel.h"
#include "solver/rotation.h"

namespace femb {

namespace dynamic_internal {

Eigen::VectorXd DriveForces(const DofMap& dofs, const Eigen::VectorXd& residual) {
  Eigen::VectorXd f;
  DriveForces(dofs, residual, f);
  return f;
}

void DriveForces(const DofMap& dofs, const Eigen::VectorXd& residual, Eigen::VectorXd& f) {
  f.setZero(residual.size());
  for (int j = 0; j < dofs.n_dofs(); ++j)
    if (dofs.prescribed(j)) f[j] = -residual[j];
}

}  // namespace dynamic_internal

using namespace dynamic_internal;

namespace {

// The free accelerations from M_g Wdot = f_ext - f_int - f_gyro at s (prescribed ones as set),
// a = Wdot, and the external and drive forces there: the start of an integration, and its
// restart at a breakpoint. The residual is taken with the free accelerations zero, so that it is
// the right-hand side whatever accelerations s held (a restart holds the integrator's): with
// them in, it would be solved for the change of the accelerations and taken as the accelerations.
void ConsistentAccelerations(const SystemModel& model, const DofMap& dofs, DynamicState& s) {
  for (int j : dofs.solved()) s.Wdot[j] = 0.0;
  const Assembly b = AssembleDynamic(model, dofs, s, s.t, true);
  Eigen::VectorXd rhs = b.residual;  // f - M Wdot_p - G^T lambda
  SystemMatrix M = b.M;
  if (dofs.n_multipliers() > 0) {
    // Closed loops: [M G^T; G 0] [Wdot_f; d lambda] = [r; -Gdot W] (the constraints' second time
    // derivative, G Wdot + Gdot W = 0), with Gdot W = d^2 g / dt^2 along q(t) = q + t W (no
    // coordinate acceleration), by central differences over a step that moves the model by 1e-4
    // of its size.
    Triplets G;
    AddLoopConstraints(model, dofs, s.config, nullptr, nullptr, nullptr, &G);
    M = b.M + ToMatrix(dofs.n_dofs(), G);
    const double L = ModelSize(model);
    double speed = 0.0;
    for (int k = 0; k < model.n_nodes(); ++k)
      speed = std::max(
          speed, NodeMotion(s.config, k, s.W).head<3>().norm() + L * NodeMotion(s.config, k, s.W).tail<3>().norm());
    const int m = dofs.n_multipliers();
    rhs.tail(m).setZero();
    if (speed > 0) {
      const double eps = 1e-4 * L / speed;
      const auto g_at = [&](double e) {
        SystemState q = s.config;
        if (e != 0.0) ApplyIncrement(model, dofs, e * s.W, q);
        Eigen::VectorXd r = Eigen::VectorXd::Zero(dofs.n_dofs());
        q.lambda.setZero();
        AddLoopConstraints(model, dofs, q, &r, nullptr, nullptr);
        return Eigen::VectorXd(-r.tail(m));  // g
      };
      rhs.tail(m) -= (g_at(eps) - 2 * g_at(0.0) + g_at(-eps)) / (eps * eps);
    }
  }
  const Eigen::VectorXd free_acc = SolveFree(dofs, M, rhs);  // zero on the prescribed coordinates
  // The drives' forces with the accelerations and multipliers found: -(r - M Wdot_f - G^T d lambda)
  // on the prescribed rows.
  s.f_drive = DriveForces(dofs, b.residual - M * free_acc);
  for (int j : dofs.solved()) s.Wdot[j] = free_acc[j];
  if (dofs.n_multipliers() > 0) {
    s.config.lambda += free_acc.tail(dofs.n_multipliers());
    dofs.ClearMultipliers(s.Wdot);
  }
  s.a = s.Wdot;
  s.f_ext = b.f_ext;
}

}  // namespace

bool AccelerationsConsistent(const SystemModel& model, const DynamicState& state) {
  return model.dofs().n_multipliers() == 0 && state.node_w.empty();
}

DynamicState WithConsistentAccelerations(const SystemModel& model, const DynamicState& state) {
  DynamicState s = state;
  if (!AccelerationsConsistent(model, state)) ConsistentAccelerations(model, model.dofs(), s);
  return s;
}

std::vector<Eigen::Matrix<double, 6, 1>> DynamicReactions(const SystemModel& model, const DynamicState& state) {
  const DofMap& dofs = model.dofs();
  DynamicState s = state;
  const Assembly a = AssembleDynamic(model, dofs, s, s.t, false);
  if (!a.ok) return std::vector<Eigen::Matrix<double, 6, 1>>(model.n_nodes(), Eigen::Matrix<double, 6, 1>::Zero());
  return JointReactions(model, dofs, s.config, a.node_forces);
}

DynamicState InitialDynamicState(const SystemModel& model, const SystemState& config, const Eigen::VectorXd& W,
                                 double t0) {
  const DofMap& dofs = model.dofs();
  DynamicState s;
  s.config = config;
  s.W = W;
  s.Wdot = Eigen::VectorXd::Zero(dofs.n_dofs());
  s.t = t0;
  ApplyPrescribed(model, dofs, t0, s.config, &s.W, &s.Wdot);
  // Driven start: when no free coordinate was given a velocity but prescribed ones move, start
  // the free ones with the velocity that makes the elastic forces stationary, K_ff W_f =
  // -K_fp W_p (the mechanism moves as a whole, no deformation rate) instead of at rest, which
  // would be an impulsive start.
  bool free_at_rest = true, driven = false;
  for (int j = 0; j < dofs.n_dofs(); ++j) {
    if (dofs.prescribed(j))
      driven |= s.W[j] != 0.0;
    else
      free_at_rest &= s.W[j] == 0.0;
  }
  if (driven && free_at_rest) {
    SystemState copy = s.config;
    const SystemForces f = AssembleStatic(model, dofs, copy, t0, true);
    Eigen::VectorXd rhs = -(f.tangent * s.W);
    const Eigen::VectorXd W_free = SolveFree(dofs, f.tangent, rhs);
    for (int j : dofs.solved()) s.W[j] = W_free[j];
    dofs.ClearMultipliers(s.W);  // (with loops their rows made G W = 0)
  } else if (dofs.n_multipliers() > 0) {
    // Closed loops with given velocities: the nearest velocities in the kinetic-energy norm that
    // keep the loops closed, W_f + d with [M G^T; G 0] [d; mu] = [0; -G W] (prescribed rates kept).
    Triplets G;
    AddLoopConstraints(model, dofs, s.config, nullptr, nullptr, nullptr, &G);
    const SystemMatrix Gm = ToMatrix(dofs.n_dofs(), G);
    const Eigen::VectorXd GW = Gm * s.W;  // the multipliers' rows: G W (W's multiplier entries are 0)
    if (GW.tail(dofs.n_multipliers()).lpNorm<Eigen::Infinity>() > 0) {
      DynamicState copy = s;
      const Assembly b = AssembleDynamic(model, dofs, copy, t0, true);
      Eigen::VectorXd rhs = Eigen::VectorXd::Zero(dofs.n_dofs());
      rhs.tail(dofs.n_multipliers()) = -GW.tail(dofs.n_multipliers());
      const Eigen::VectorXd d = SolveFree(dofs, SystemMatrix(b.M + Gm), rhs);
      for (int j : dofs.solved())
        if (!dofs.multiplier(j)) s.W[j] += d[j];
    }
  }
  ConsistentAccelerations(model, dofs, s);
  return s;
}

double HighestFrequency(const SuperelementBody& body) {
  if (body.K().rows() == 0 || body.K().cwiseAbs().maxCoeff() == 0.0) return 0.0;  // rigid bodies
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(body.K(), body.M(), Eigen::EigenvaluesOnly);
  if (eig.info() != Eigen::Success) return 0.0;
  return std::sqrt(std::max(eig.eigenvalues().maxCoeff(), 0.0));
}

namespace {
// The midpoint scheme conserves energy: it damps no mode, and a mode whose period spans fewer
// than 2 pi steps (omega h > 1) it does not resolve either; excited by the motion, such modes
// ring undamped in the reactions and stresses. Measured on a tilted four-bar with a flexible
// coupler (highest reduced-model frequency 11.7 kHz) against its own 5 us run: the ground
// reactions 3.4e-3 of their peak off at omega h = 1.5 (20 us), 9e-2 at 7.3, 9 times the peak at
// 73; generalized-alpha (rho_inf 0.8) 6.7e-4 at 73. Empty when every body's highest frequency
// (its reduced K and M) is resolved at the largest step h.
std::string UnresolvedModesWarning(const SystemModel& model, double h) {
  double omega = 0.0;
  int worst = -1;
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    const double w = HighestFrequency(model.bodies[b]);
    if (w > omega) omega = w, worst = int(b);
  }
  if (worst < 0 || omega * h <= 1.0) return "";
  const std::string name = size_t(worst) < model.body_names.size() ? "'" + model.body_names[size_t(worst)] + "'"
                                                                   : "number " + std::to_string(worst + 1);
  char buffer[700];
  std::snprintf(buffer, sizeof buffer,
                "the midpoint integrator neither damps nor resolves body %s's highest mode, %.4g Hz, at steps of up to "
                "%.3g s (omega h = %.3g, fewer than 2 pi steps a period): excited, such modes ring undamped in the "
                "reactions and stresses. Use steps below %.3g s (omega h < 1; step: auto without max_step keeps "
                "them at 0.7 / omega), or analysis.integrator: generalized_alpha, whose rho_inf damps them",
                name.c_str(), omega / (2 * M_PI), h, omega * h, 1.0 / omega);
  return buffer;
}

// The step's measures with `passes` the converged iteration's (nothing evaluated: each body's
// share on the threads into `work.measures`, then summed in body order, the same bits for any
// number of threads), or, without them (none, passes of another size, or no `measures`), each
// body evaluated here.
DynamicStepReport MeasureWith(const SystemModel& model, const DofMap& dofs, const DynamicState& s,
                              std::vector<BodyPass>* passes, BodyThreads* threads = nullptr,
                              std::vector<BodyMeasure>* measures = nullptr, SystemScratch* scratch = nullptr) {
  DynamicStepReport r;
  r.t = s.t;
  r.external_work = s.external_work;
  if (!model.springs.empty()) {
    AddSpringDampers(model, s.config, s.W, nullptr, nullptr, nullptr, &r.elastic_energy, nullptr, scratch);  // springs
  }
  const int n_bodies = int(model.bodies.size());
  const auto measure = [&](int b, BodyData& data, const Eigen::VectorXd& w, BodyMeasure& m) {
    const SuperelementBody& body = model.bodies[size_t(b)];
    const Eigen::VectorXd& p = MassTimes(body, data, w);  // M_g w, once for the energy and the momenta
    m.kinetic = 0.5 * w.dot(p);
    MomentumFrom(body, data, p, &m.linear, &m.angular);
    m.elastic = ElasticEnergy(body, data);
  };
  const auto add = [&](const BodyMeasure& m) {
    r.kinetic_energy += m.kinetic;
    r.elastic_energy += m.elastic;
    r.linear_momentum += m.linear;
    r.angular_momentum += m.angular;
  };
  if (passes && passes->size() == model.bodies.size() && measures) {
    measures->resize(size_t(n_bodies));
    std::vector<BodyPass>& kept = *passes;
    ForEachBody(threads, n_bodies, [&](int b) { measure(b, kept[size_t(b)].data, kept[size_t(b)].w, (*measures)[b]); });
    for (const BodyMeasure& m : *measures) add(m);
    return r;
  }
  for (int b = 0; b < n_bodies; ++b) {
    BodyMeasure m;
    BodyData data = Evaluate(model.bodies[size_t(b)], BodyConfigurationOf(model, s.config, b), s.config.frames[b]);
    measure(b, data, BodyVelocityOf(model, dofs, s, b), m);
    add(m);
  }
  return r;
}
// The kinetic energy of velocities at the noise of the positions' round-off over a step h (the
// energy watchdog's floor in SolveDynamic).
double EnergyNoise(double mass, const SystemState& config, double h) {
  double x = 0.0;
  for (const Eigen::Vector3d& xk : config.x) x = std::max(x, xk.norm());
  const double v = 100.0 * std::numeric_limits<double>::epsilon() * x / h;
  return 0.5 * mass * v * v;
}
}  // namespace

DynamicStepReport Measure(const SystemModel& model, DynamicState& s) { return MeasureWith(model, model.dofs(), s, {}); }

namespace {

using OnStep = std::function<void(const DynamicStepReport&, const DynamicState&)>;

// Energy balance E = T + U - W_loads - W_drives: constant for a conservative system, falling
// with damping (modal, dampers, generalized-alpha's rho_inf < 1). Growth is numerical: a step
// too long for the stiffest modes (generalized-alpha with rho_inf near 1 on stiff modes; the
// midpoint scheme's elastic force is not an exact discrete gradient). Above 5% of the energy
// scale (the largest of T + U and the works so far) it is said once; above 25% the run stops.
// The energy scale has a floor: the kinetic energy of velocities at the noise of the
// positions' round-off over a step, E_noise = m |v_noise|^2 / 2 with v_noise = 100 eps |x|_max
// / h (m the bodies' mass, |x|_max the largest node distance from the origin), so that a start
// from rest is not judged on noise: the spin-up of a four-bar (0.45 kg, 0.4 m) at h = 2 us held
// 2e-21 J of kinetic energy after its first step, all of it noise (the drive's work was
// 3e-26 J), and 1e-20 J after ten; E_noise is 4e-18 J there, and 1e-25 J at h = 1 ms. A second
// floor is the drives' work's round-off (WatchEnergy): at the start of a spin-up their reactions
// are at Newton's floor, and the rigid tilted four-bar's at h = 5 us did 5.7e-18 J of noise work
// by t = 95 us, 5% of the 1.0e-16 J it held.
constexpr double kEnergyWarn = 0.05, kEnergyStop = 0.25;

// One run of SolveDynamic: the time loop's state between steps. Run() takes steps until the end
// time, a stop request or a failure: each step is tried (TryStep), judged (Newton's outcome, the
// error estimate), placed on the time grid (PlaceStep), taken over (Accept), measured and watched
// (Report), and the next step's size chosen (NextStepSize).
class DynamicRun {
 public:
  DynamicRun(const SystemModel& model, DynamicState& state, const DynamicOptions& options, const OnStep& on_step)
      : model_(model),
        dofs_(model.dofs()),
        state_(state),
        options_(options),
        on_step_(on_step),
        resume_(options.resume),
        control_(model, dofs_, options, resume_ ? resume_->t_start : state.t),
        threads_(options.threads),
        n_bodies_(int(model.bodies.size())) {}

  DynamicResult Run() {
    if (resume_) state_ = resume_->state;
    h_ = options_.adaptive ? control_.FirstStep() : options_.step;
    t_base_ = state_.t;
    t_output0_ = resume_ ? resume_->t_start : state_.t;
    const DynamicStepReport start = resume_ ? DynamicStepReport() : Measure(model_, state_);
    E0_ = resume_ ? resume_->E0 : start.kinetic_energy + start.elastic_energy;
    energy_scale_ = resume_ ? resume_->energy_scale : std::abs(E0_);
    for (const SuperelementBody& body : model_.bodies) model_mass_ += std::max(body.mass(), 0.0);
    if (const std::string w = RoundOffToleranceWarning(options_.tolerance); !w.empty()) {
      result_.warnings.push_back(w);
    }
    if (resume_ && !Resume()) return result_;
    grid_time_ = state_.t;
    capture_ = [this](DynamicResume& r) { Capture(r); };
    while (BeforeEnd()) {
      FitStep();
      const double t_new = options_.adaptive && control_.at_breakpoint()
                               ? std::nextafter(control_.boundary(), -HUGE_VAL)
                               : state_.t + h_;
      const StepOutcome step = TryStep(t_new);
      if (!step.converged && result_.steps == 0 && result_.newton_cuts == 0 && step.singular_matrix) {
        // The first iteration matrix is singular: the model's, not the step's.
        const std::string why = DescribeSingular(model_, dofs_, state_.config, *step.singular_matrix);
        if (!why.empty()) {
          result_.message = "iteration matrix at the start: " + why;
          return result_;
        }
      }
      std::string failure;
      double error = 0.0;
      if (!Judge(step, &error, &failure)) {
        if (!failure.empty()) return Fail(failure);
        continue;
      }
      const bool output = PlaceStep();
      Accept(step);
      DynamicStepReport r = Report(step, output);
      const std::string unstable = WatchEnergy(r);
      NextStepSize(step, error);
      // A stop requested by now ends the run after this report (one requested during it, after
      // the next step): the report says which step is the last.
      const int stop = options_.stop ? options_.stop->load() : 0;
      r.last = !BeforeEnd() || stop != 0;
      if (on_step_) on_step_(r, state_);
      if (!unstable.empty()) return Fail(unstable);
      if (stop != 0) {
        result_.stopped = stop;
        break;
      }
    }
    CountFactorizations();
    FinalWarnings();
    result_.ok = true;
    return result_;
  }

 private:
  // The loop's variables, the step controller, the pivot order, the bodies' last frame matrices
  // and kept matrices as the saved run had them after its last step. false with result_.message.
  bool Resume() {
    const DynamicResume& r = *resume_;
    h_ = r.h, cuts_ = r.cuts, t_base_ = r.t_base, n_nominal_ = r.n_nominal;
    last_output_ = r.last_output, first_cut_time_ = r.first_cut_time, warned_ = r.warned;
    result_ = r.result;
    control_.Restore(r);
    if (!matrix_.solver.Restore(r.factor)) {
      result_.message = "the saved state's iteration matrix pivots could not be restored";
      return false;
    }
    matrix_.factorizations = r.factorizations;
    work_.matrices_computed = r.matrices_computed, work_.matrices_turned = r.matrices_turned;
    work_.passes.resize(size_t(n_bodies_));
    work_.matrices.resize(size_t(n_bodies_));
    for (int b = 0; b < n_bodies_; ++b) {
      if (size_t(b) < r.has_frame_S_inv.size() && r.has_frame_S_inv[size_t(b)]) {
        work_.passes[size_t(b)].data.kin.S_inv = r.frame_S_inv[size_t(b)];
        work_.passes[size_t(b)].data.kin.W.resize(6, model_.bodies[size_t(b)].n_coordinates());
      }
      if (size_t(b) < r.kept_age.size()) {
        BodyWorkspace::BodyMatrices& m = work_.matrices[size_t(b)];
        m.M_frame = r.kept_M[size_t(b)], m.C_frame = r.kept_C[size_t(b)];
        m.K_frame = r.kept_K[size_t(b)], m.age = r.kept_age[size_t(b)];
      }
    }
    MidpointWorkspace& mw = work_.midpoint;
    if (!r.closure_dc.empty()) mw.bodies.resize(size_t(n_bodies_));
    for (size_t b = 0; b < r.closure_dc.size() && b < mw.bodies.size(); ++b) {
      mw.bodies[b].dc = r.closure_dc[b], mw.bodies[b].dc_fresh = r.closure_dc_fresh[b] != 0;
    }
    return true;
  }

  // What the next step starts from (DynamicStepReport::capture, called in on_step). A fixed
  // step's time is t_base + n h, rounded to end_time at the end for the report: the state goes
  // on from the unrounded one (grid_time_), as in a longer run.
  void Capture(DynamicResume& r) const {
    r.state = state_;
    if (!options_.adaptive) r.state.t = grid_time_;
    r.t_start = t_output0_, r.h = h_, r.t_base = t_base_, r.last_output = last_output_, r.E0 = E0_;
    r.energy_scale = energy_scale_, r.first_cut_time = first_cut_time_, r.n_nominal = n_nominal_, r.cuts = cuts_;
    r.warned = warned_;
    r.result = result_;
    control_.Save(r);
    matrix_.solver.Save(r.factor);
    r.factorizations = matrix_.factorizations;
    r.matrices_computed = work_.matrices_computed, r.matrices_turned = work_.matrices_turned;
    r.frame_S_inv.assign(size_t(n_bodies_), Eigen::Matrix<double, 6, 6>::Zero());
    r.has_frame_S_inv.assign(size_t(n_bodies_), 0);
    for (int b = 0; b < n_bodies_ && size_t(b) < work_.passes.size(); ++b) {
      const BodyKinematics& kin = work_.passes[size_t(b)].data.kin;
      if (kin.W.cols() != model_.bodies[size_t(b)].n_coordinates()) continue;
      r.frame_S_inv[size_t(b)] = kin.S_inv;
      r.has_frame_S_inv[size_t(b)] = 1;
    }
    r.kept_M.clear(), r.kept_C.clear(), r.kept_K.clear(), r.kept_age.clear();
    for (const BodyWorkspace::BodyMatrices& m : work_.matrices) {
      r.kept_M.push_back(m.M_frame), r.kept_C.push_back(m.C_frame), r.kept_K.push_back(m.K_frame);
      r.kept_age.push_back(m.age);
    }
    r.closure_dc.clear(), r.closure_dc_fresh.clear();
    for (const MidpointBody& m : work_.midpoint.bodies) {
      r.closure_dc.push_back(m.dc_fresh ? m.dc : Eigen::MatrixXd()), r.closure_dc_fresh.push_back(char(m.dc_fresh));
    }
  }

  void CountFactorizations() {
    result_.factorizations = matrix_.factorizations;
    result_.pattern_analyses = matrix_.solver.analyses();
    result_.pivoted = matrix_.solver.full_factorizations();
    result_.body_matrices_computed = work_.matrices_computed;
    result_.body_matrices_turned = work_.matrices_turned;
  }

  DynamicResult Fail(const std::string& message) {
    result_.message = message;
    if (const std::string why = LoopSingularity(model_, state_.config); !why.empty()) result_.message += "; " + why;
    CountFactorizations();
    return result_;
  }

  bool BeforeEnd() const {
    return state_.t < options_.end_time - 1e-12 * std::max(std::abs(options_.end_time), options_.step);
  }

  // The step to try: the controller's, fitted to the next boundary; or the fixed step, the last
  // one the rest of the time unless that is the nominal step to round-off (then the step stays
  // nominal: a run extended from this end takes the steps a longer run takes).
  void FitStep() {
    if (options_.adaptive) {
      h_ = control_.Fit(state_.t, h_);
    } else {
      const double remaining = options_.end_time - state_.t;
      if (remaining <= 1.01 * h_ && !(h_ == options_.step && std::abs(remaining - h_) <= 1e-9 * h_)) h_ = remaining;
    }
    matrix_.with_this_factor = 0;  // a step may use the kept factor for reuse_max_iterations iterations
  }

  StepOutcome TryStep(double t_new) {
    return IntegratorStep(model_, dofs_, options_, state_, h_, t_new, matrix_, threads_, work_, next_);
  }

  // Whether the step stands: Newton converged and, with error-controlled steps, the error
  // estimate (into *error) within the tolerance. Otherwise the step is shortened for a retry, or
  // *failure says why the run cannot go on.
  bool Judge(const StepOutcome& step, double* error, std::string* failure) {
    if (!step.converged && options_.adaptive) {
      matrix_.solver.Invalidate();
      ++result_.newton_cuts;
      after_rejection_ = true;
      if (0.5 * h_ < control_.min_step()) {
        char buffer[200];
        std::snprintf(buffer, sizeof buffer, "Newton diverged at t = %.6g with step %.3g (min_step %.3g)", state_.t, h_,
                      control_.min_step());
        *failure = buffer;
        return false;
      }
      h_ *= 0.5;
      return false;
    }
    if (options_.adaptive) {
      *error = step.error_q ? control_.Error(*step.error_q, *step.error_v) : control_.Error(state_, next_, h_);
      if (*error > 1.0) {
        ++result_.rejected_by_error;
        after_rejection_ = true;
        const double h_new = h_ * control_.RetryFactor(*error);
        if (h_new < control_.min_step()) {
          char buffer[300];
          std::snprintf(buffer, sizeof buffer,
                        "the step fell below min_step %.3g at t = %.6g (estimated local error %.3g times "
                        "step_tolerance with step %.3g)",
                        control_.min_step(), state_.t, *error, h_);
          *failure = buffer;
          return false;
        }
        h_ = h_new;
        return false;
      }
      next_.t = control_.lands() ? control_.boundary() : state_.t + h_;
    }
    if (!step.converged) {
      matrix_.solver.Invalidate();
      ++result_.newton_cuts;
      if (cuts_ >= options_.max_cuts) {
        char buffer[200];
        std::snprintf(buffer, sizeof buffer, "Newton diverged at t = %.6g after %d step cuts (step %.3g)", state_.t,
                      cuts_, h_);
        *failure = buffer;
        return false;
      }
      h_ *= 0.5;
      ++cuts_;
      return false;
    }
    return true;
  }

  // The accepted step's time (fixed steps: on the grid t_base + n h while the step stays
  // nominal; summing h over 1e6 steps drifted by 1e-8 s and left a last step of 1e-8 s that
  // Newton could not take, and a remainder below 1% of a step is merged into the last one) and
  // whether it is an output step.
  bool PlaceStep() {
    if (options_.adaptive) return control_.output();
    if (h_ == options_.step) {
      next_.t = t_base_ + double(++n_nominal_) * options_.step;
    } else {
      t_base_ = next_.t;
      n_nominal_ = 0;
    }
    grid_time_ = next_.t;  // a run continued from here goes on from the unrounded time
    if (options_.end_time - next_.t < 1e-9 * h_) next_.t = options_.end_time;
    if (options_.output_step <= 0) return true;
    // The first step at or after each output time.
    const double k = std::floor((next_.t - t_output0_) / options_.output_step + 1e-9);
    const bool output = k > last_output_ || next_.t >= options_.end_time;
    if (output) last_output_ = k;
    return output;
  }

  // The step's end becomes the state; at a breakpoint (a load or drive jumps or kinks there) the
  // run restarts from it with the accelerations of the right limit, as at the start, so that no
  // step sees the jump inside it. Generalized-alpha keeps what a_n carries beyond the motion's own
  // acceleration, (alpha_m - alpha_f) h q3 (q3 the motion's third derivative;
  // generalized_alpha.cpp): taken away, the stiff directions of flexible bodies take the change as
  // at a change of step.
  void Accept(const StepOutcome& step) {
    next_.h_last = h_;
    restarted_ = false;
    if (result_.steps == 0 || h_ < result_.smallest_step)
      result_.smallest_step = h_, result_.smallest_step_time = next_.t;
    result_.largest_step = std::max(result_.largest_step, h_);
    if (cuts_ > 0 && first_cut_time_ < 0) first_cut_time_ = state_.t;
    state_ = next_;
    if (options_.adaptive && control_.at_breakpoint()) {
      ApplyPrescribed(model_, dofs_, state_.t, state_.config, &state_.W, &state_.Wdot, &work_.parts.scratch);
      if (options_.integrator == Integrator::kGeneralizedAlpha) work_.a_n = state_.a - state_.Wdot;
      ConsistentAccelerations(model_, dofs_, state_);
      restarted_ = true;
      if (options_.integrator == Integrator::kGeneralizedAlpha) {
        state_.a += work_.a_n;
        state_.increments_kept = 0;  // the motion's third derivative jumps here
      } else if (options_.integrator == Integrator::kRadau) {
        state_.increments_kept = 0;  // as the accelerations' polynomial, which Radau's predictor extends
      } else {
        state_.h_last = 0.0;
      }
    }
    result_.steps += 1;
    result_.newton_iterations += step.iterations;
  }

  // The step's report: energies and momenta from the converged pass where the step kept it.
  DynamicStepReport Report(const StepOutcome& step, bool output) {
    DynamicStepReport r = MeasureWith(model_, dofs_, state_, step.passes_kept ? &work_.passes : nullptr, &threads_,
                                      &work_.measures, &work_.parts.scratch);
    r.h = h_;
    r.iterations = step.iterations;
    r.rejected = result_.rejected_by_error + result_.newton_cuts;
    r.output = output;
    r.capture = &capture_;
    if (options_.integrator == Integrator::kGeneralizedAlpha && step.passes_kept && !restarted_)
      r.node_forces = &work_.assembly.node_forces;
    return r;
  }

  // The energy watchdog (kEnergyWarn, kEnergyStop): the message that stops the run, or empty.
  // Judged from the 10th step on: over the first few steps of a smooth start (a spin-up drive,
  // energy ~ t^6) the trapezoidal work of the drives is off by tens of percent of an energy that
  // is itself round-off (a one-body spin-up stopped at t = 0.01 with 2.4e-16 J of 4.1e-16 J); the
  // rule's error falls as 1/n^2 of the steps taken.
  std::string WatchEnergy(const DynamicStepReport& r) {
    const double energy = r.kinetic_energy + r.elastic_energy;
    // The drives' work has the round-off of their forces (the prescribed rows of the residual, at
    // Newton's floor where the motion is slow): their relative round-off times the work so far
    // (the scale keeps the largest, so a noisy start counts on).
    const double f_drive = state_.f_drive.size() ? state_.f_drive.norm() : 0.0;
    const double drive_noise =
        f_drive > 0 ? std::abs(state_.drive_work) * std::min(1.0, work_.assembly.roundoff / f_drive) : 0.0;
    energy_scale_ =
        std::max({energy_scale_, std::abs(energy), std::abs(state_.external_work), std::abs(state_.drive_work),
                  EnergyNoise(model_mass_, state_.config, h_) / kEnergyWarn, drive_noise / kEnergyWarn});
    const double growth = energy - state_.external_work - state_.drive_work - E0_;
    if (!(result_.steps >= 10 && energy_scale_ > 0 && growth > kEnergyWarn * energy_scale_)) return "";
    char buffer[400];
    std::snprintf(buffer, sizeof buffer,
                  "the energy grew by %.3g (%.1f%% of %.3g) at t = %.6g beyond the work of the loads and drives: "
                  "numerically unstable at step %.3g; reduce analysis.%s%s",
                  growth, 100 * growth / energy_scale_, energy_scale_, state_.t, h_,
                  options_.adaptive ? "step_tolerance" : "step",
                  options_.integrator == Integrator::kGeneralizedAlpha ? " or analysis.rho_inf" : "");
    if (growth > kEnergyStop * energy_scale_) return buffer;
    if (!warned_) result_.warnings.push_back(buffer);
    warned_ = true;
    return "";
  }

  // The next step's size, before the report goes out: what on_step captures is what the next
  // step starts from.
  void NextStepSize(const StepOutcome& step, double error) {
    if (options_.adaptive) {
      h_ = control_.Accept(state_, h_, error, after_rejection_);
      after_rejection_ = false;
    } else if (cuts_ > 0 && step.iterations <= 4) {
      h_ = std::min(options_.step, 2 * h_);
      --cuts_;
    }
  }

  // The midpoint scheme's unresolved modes, and a fixed step that Newton could not take (said
  // once, with the step used).
  void FinalWarnings() {
    if (options_.integrator == Integrator::kMidpoint) {
      if (const std::string w = UnresolvedModesWarning(model_, result_.largest_step); !w.empty())
        result_.warnings.push_back(w);
    }
    if (!options_.adaptive && first_cut_time_ >= 0) {
      char buffer[400];
      std::snprintf(buffer, sizeof buffer,
                    "Newton did not converge with analysis.step %.3g from t = %.6g on (%ld cuts): steps there were "
                    "shortened, to %.3g at the least (at t = %.6g); the results are those of the shorter steps. Give "
                    "a step Newton takes, or `step: auto`",
                    options_.step, first_cut_time_, result_.newton_cuts, result_.smallest_step,
                    result_.smallest_step_time);
      result_.warnings.push_back(buffer);
    }
  }

  const SystemModel& model_;
  const DofMap& dofs_;
  DynamicState& state_;
  const DynamicOptions& options_;
  const OnStep& on_step_;
  const DynamicResume* resume_;
  DynamicResult result_;
  StepController control_;
  double h_ = 0.0;
  int cuts_ = 0;
  bool after_rejection_ = false;
  bool restarted_ = false;  ///< the last accepted step ended at a breakpoint's restart
  IterationMatrix matrix_;
  BodyThreads threads_;
  BodyWorkspace work_;
  DynamicState next_;  ///< the step's result; its storage is reused from step to step
  // Time is counted in steps on fixed steps: t = t_base_ + n_nominal_ h while the step stays
  // nominal (PlaceStep).
  double t_base_ = 0.0;
  long n_nominal_ = 0;
  double t_output0_ = 0.0, last_output_ = 0.0;
  double E0_ = 0.0, energy_scale_ = 0.0;
  double first_cut_time_ = -1.0;  ///< fixed steps: where Newton first needed a shorter step
  double model_mass_ = 0.0;
  bool warned_ = false;
  const int n_bodies_;
  double grid_time_ = 0.0;
  std::function<void(DynamicResume&)> capture_;
};

}  // namespace

DynamicResult SolveDynamic(const SystemModel& model, DynamicState& state, const DynamicOptions& options,
                           const OnStep& on_step) {
  DynamicRun run(model, state, options, on_step);
  return run.Run();
}

}  // namespace femb
