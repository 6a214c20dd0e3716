#include "solver/analysis/dynamic_analysis.h"

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>

namespace femb {
namespace {

struct Assembly {
  bool ok = true;
  std::string message;
  Eigen::VectorXd residual;  // f_ext + f_grav - f_int - f_in
  Eigen::VectorXd f_ext;     // nodal loads and gravity, for the work
  SystemMatrix K, C, M;
  double scale = 0.0;
};

Assembly AssembleDynamic(const SystemModel& model, const DofMap& dofs, DynamicState& s, double t, bool matrices) {
  Assembly out;
  const int n = dofs.n_dofs();
  out.residual = Eigen::VectorXd::Zero(n);
  out.f_ext = Eigen::VectorXd::Zero(n);
  Triplets K, C, M;
  NodeForces node_forces = ZeroNodeForces(model);
  const std::vector<Eigen::Matrix<double, 6, 1>> node_acc = NodeAccelerations(model, dofs, s.config, s.W, s.Wdot);
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    const SuperelementBody& body = model.bodies[b];
    const BodyConfiguration c = BodyConfigurationOf(model, s.config, int(b));
    FrameSolution frame = body.SolveFrame(c, s.config.frames[b]);
    if (!frame.ok) frame = body.SolveFrame(c, body.GuessFrame(c));
    if (!frame.ok) {
      out.ok = false;
      out.message = "floating frame of body " + std::to_string(b) + " did not converge";
      return out;
    }
    s.config.frames[b] = frame;
    const Eigen::VectorXd w = GatherBody(model, dofs, s.config, int(b), s.W);
    const Eigen::VectorXd wdot = GatherBodyAcceleration(model, dofs, int(b), node_acc, s.Wdot);
    Eigen::VectorXd f_int, f_in;
    Eigen::MatrixXd Kb, Mb, Cb;
    body.ElasticForce(c, frame, &f_int, matrices ? &Kb : nullptr);
    body.InertiaForce(c, frame, w, wdot, &f_in, matrices ? &Mb : nullptr, matrices ? &Cb : nullptr);
    body.AddModalDamping(w, f_in, matrices ? &Cb : nullptr);
    Eigen::VectorXd f_grav = Eigen::VectorXd::Zero(body.n_coordinates());
    if (model.gravity.squaredNorm() > 0) f_grav = body.GravityForce(c, frame, model.gravity);
    // Scale of the forces in balance, each term on its own (for a torque-free body M_g wdot and
    // the gyroscopic terms cancel: their sum is no scale).
    out.scale = std::max({out.scale, f_int.norm(), f_in.norm(), f_grav.norm(), body.force_floor()});
    if (matrices) {
      const Eigen::VectorXd f_acc = Mb * wdot;
      out.scale = std::max({out.scale, f_acc.norm(), (f_in - f_acc).norm()});
    }
    const std::vector<MapEntry> map = BodyMap(model, dofs, s.config, int(b));
    const Eigen::VectorXd r_b = f_grav - f_int - f_in;
    AddBodyNodeForces(model, int(b), r_b, node_forces);
    ScatterBody(map, &r_b, nullptr, &out.residual, nullptr);
    ScatterBody(map, &f_grav, nullptr, &out.f_ext, nullptr);
    if (matrices) {
      ScatterBody(map, nullptr, &Kb, nullptr, &K);
      ScatterBody(map, nullptr, &Cb, nullptr, &C);
      ScatterBody(map, nullptr, &Mb, nullptr, &M);
    }
  }
  Eigen::VectorXd loads = Eigen::VectorXd::Zero(n);
  AddNodeLoads(model, s.config, t, loads, matrices ? &K : nullptr, &node_forces);
  out.residual += loads;
  out.f_ext += loads;
  Eigen::VectorXd springs = Eigen::VectorXd::Zero(n);
  AddSpringDampers(model, s.config, s.W, springs, matrices ? &K : nullptr, matrices ? &C : nullptr,
                   nullptr, &node_forces);
  out.residual += springs;
  out.scale = std::max(out.scale, springs.norm());
  if (matrices) {
    AddJointGeometricStiffness(model, dofs, s.config, node_forces, K);
    out.K = ToMatrix(n, K);
    out.C = ToMatrix(n, C);
    out.M = ToMatrix(n, M);
  }
  out.scale = std::max({out.scale, loads.norm(), 1e-300});
  return out;
}

}  // namespace

DynamicState InitialDynamicState(const SystemModel& model, const SystemState& config, const Eigen::VectorXd& W,
                                 double t0) {
  const DofMap dofs(model);
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
    if (dofs.prescribed(j)) driven |= s.W[j] != 0.0;
    else free_at_rest &= s.W[j] == 0.0;
  }
  if (driven && free_at_rest) {
    SystemState copy = s.config;
    const SystemForces f = AssembleStatic(model, dofs, copy, t0, true);
    Eigen::VectorXd rhs = -(f.tangent * s.W);
    const Eigen::VectorXd W_free = SolveFree(dofs, f.tangent, rhs);
    for (int j : dofs.solved()) s.W[j] = W_free[j];
  }
  const Assembly b = AssembleDynamic(model, dofs, s, t0, true);
  const Eigen::VectorXd free_acc = SolveFree(dofs, b.M, b.residual - b.M * s.Wdot);
  for (int j : dofs.solved()) s.Wdot[j] = free_acc[j];
  s.a = s.Wdot;
  s.f_ext = b.f_ext;
  return s;
}

DynamicStepReport Measure(const SystemModel& model, DynamicState& s) {
  const DofMap dofs(model);
  DynamicStepReport r;
  r.t = s.t;
  r.external_work = s.external_work;
  Eigen::VectorXd unused = Eigen::VectorXd::Zero(dofs.n_dofs());
  AddSpringDampers(model, s.config, s.W, unused, nullptr, nullptr, &r.elastic_energy);  // spring energy
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    const SuperelementBody& body = model.bodies[b];
    const BodyConfiguration c = BodyConfigurationOf(model, s.config, int(b));
    const FrameSolution& frame = s.config.frames[b];
    const Eigen::VectorXd w = GatherBody(model, dofs, s.config, int(b), s.W);
    r.kinetic_energy += body.KineticEnergy(c, frame, w);
    r.elastic_energy += body.ElasticEnergy(c, frame);
    Eigen::Vector3d L, H;
    body.Momentum(c, frame, w, &L, &H);
    r.linear_momentum += L;
    r.angular_momentum += H;
  }
  return r;
}

DynamicResult SolveDynamic(const SystemModel& model, DynamicState& state, const DynamicOptions& options,
                           const std::function<void(const DynamicStepReport&, const DynamicState&)>& on_step) {
  DynamicResult result;
  const DofMap dofs(model);
  const double rho = std::clamp(options.rho_inf, 0.0, 1.0);
  const double alpha_m = (2 * rho - 1) / (rho + 1), alpha_f = rho / (rho + 1);
  const double gamma = 0.5 + alpha_f - alpha_m, beta = 0.25 * (gamma + 0.5) * (gamma + 0.5);
  double h = options.step, factored_h = -1.0;
  int cuts = 0;
  FreeSolver solver;
  while (state.t < options.end_time - 1e-12 * options.end_time) {
    h = std::min(h, options.end_time - state.t);
    DynamicState next = state;
    const Eigen::VectorXd a_pred = (alpha_f * state.Wdot - alpha_m * state.a) / (1 - alpha_m);
    next.a = a_pred;
    next.Wdot.setZero();
    next.W = state.W + h * (1 - gamma) * state.a + h * gamma * a_pred;
    const Eigen::VectorXd dq = state.W + h * (0.5 - beta) * state.a + h * beta * a_pred;
    ApplyIncrement(model, dofs, h * dq, next.config);
    ApplyPrescribed(model, dofs, state.t + h, next.config, &next.W, &next.Wdot);
    const double gamma_p = gamma / (beta * h), beta_p = (1 - alpha_m) / (beta * h * h * (1 - alpha_f));
    const double t_new = state.t + h;
    bool converged = false;
    int it = 0;
    Eigen::VectorXd f_ext_new;
    if (h != factored_h) solver.Invalidate();
    int with_this_factor = 0;
    for (; it < options.max_iterations; ++it) {
      const Assembly a = AssembleDynamic(model, dofs, next, t_new, true);
      if (!a.ok || !a.residual.allFinite()) break;
      if (FreeNorm(dofs, a.residual) <= options.tolerance * a.scale && it > 0) {
        converged = true;
        f_ext_new = a.f_ext;
        break;
      }
      if (!options.reuse_jacobian || !solver.valid() || with_this_factor >= options.reuse_max_iterations) {
        const SystemMatrix S = a.K + gamma_p * a.C + beta_p * a.M;
        if (!solver.Factor(dofs, S)) break;
        factored_h = h;
        with_this_factor = 0;
        ++result.factorizations;
      }
      ++with_this_factor;
      const Eigen::VectorXd delta = solver.Solve(a.residual);
      if (!delta.allFinite()) break;
      ApplyIncrement(model, dofs, delta, next.config);
      next.W += gamma_p * delta;
      next.Wdot += beta_p * delta;
    }
    if (!converged) {
      if (cuts >= options.max_cuts) {
        char buffer[200];
        std::snprintf(buffer, sizeof buffer, "Newton diverged at t = %.6g after %d step cuts (step %.3g)",
                      state.t, cuts, h);
        result.message = buffer;
        return result;
      }
      h *= 0.5;
      ++cuts;
      continue;
    }
    next.a += (1 - alpha_f) / (1 - alpha_m) * next.Wdot;
    next.t = t_new;
    // External work by the trapezoidal rule on the increment h dq (nodal loads and gravity).
    const Eigen::VectorXd increment = h * (0.5 * (state.W + next.W));
    next.external_work += 0.5 * (state.f_ext + f_ext_new).dot(increment);
    next.f_ext = f_ext_new;
    state = next;
    result.steps += 1;
    result.newton_iterations += it;
    if (on_step) {
      DynamicStepReport r = Measure(model, state);
      r.h = h;
      r.iterations = it;
      on_step(r, state);
    }
    if (cuts > 0 && it <= 4) {
      h = std::min(options.step, 2 * h);
      --cuts;
    }
  }
  result.ok = true;
  return result;
}

}  // namespace femb
