#include "solver/analysis/dynamic_analysis.h"

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <functional>

#include "solver/analysis/dynamic_step.h"
#include "solver/analysis/singularity.h"
#include "solver/analysis/step_control.h"
#include "solver/parallel.h"
#include "solver/rotation.h"

namespace femb {

namespace dynamic_internal {

Assembly StartAssembly(const SystemModel& model, const DofMap& dofs, AssemblyParts& parts) {
  Assembly out;
  out.residual = Eigen::VectorXd::Zero(dofs.n_dofs());
  out.f_ext = Eigen::VectorXd::Zero(dofs.n_dofs());
  parts.node_forces = ZeroNodeForces(model);
  return out;
}

void FinishAssembly(const SystemModel& model, const DofMap& dofs, const SystemState& config, double t,
                    const Eigen::VectorXd& W, bool matrices, AssemblyParts& parts, Assembly& out) {
  const int n = dofs.n_dofs();
  Eigen::VectorXd loads = Eigen::VectorXd::Zero(n);
  AddNodeLoads(model, config, t, loads, matrices ? &parts.K : nullptr, &parts.node_forces);
  out.residual += loads;
  out.f_ext += loads;
  Eigen::VectorXd springs = Eigen::VectorXd::Zero(n);
  AddSpringDampers(model, config, W, springs, matrices ? &parts.K : nullptr, matrices ? &parts.C : nullptr, nullptr,
                   &parts.node_forces);
  out.residual += springs;
  if (matrices) {
    AddJointGeometricStiffness(model, dofs, config, parts.node_forces, parts.K);
    out.K = ToMatrix(n, parts.K);
    out.C = ToMatrix(n, parts.C);
    out.M = ToMatrix(n, parts.M);
  }
  const Eigen::VectorXd w = ResidualWeights(model, dofs);
  out.scale = std::max({out.scale, (w.asDiagonal() * springs).norm(), (w.asDiagonal() * loads).norm(), 1e-300});
  out.node_forces = parts.node_forces;
}

void ForEachBody(BodyThreads* threads, int n, const std::function<void(int)>& f) {
  if (threads) {
    threads->ForEach(n, f);
  } else {
    for (int b = 0; b < n; ++b) f(b);
  }
}

bool AddBodyTerms(const SystemModel& model, const std::vector<BodyTerms>& terms, AssemblyParts& parts, Assembly& out) {
  for (size_t b = 0; b < terms.size(); ++b) {
    const BodyTerms& r = terms[b];
    if (!r.frame_ok) {
      out.ok = false;
      out.message = "floating frame of body " + std::to_string(b) + " did not converge";
      return false;
    }
    out.scale = std::max(out.scale, r.scale);
    out.roundoff += r.roundoff;
    AddBodyNodeForces(model, int(b), r.r_b, parts.node_forces);
    const bool matrices = r.K.size() > 0;
    ScatterBody(r.map, &r.r_b, matrices ? &r.K : nullptr, &out.residual, matrices ? &parts.K : nullptr);
    ScatterBody(r.map, &r.f_grav, matrices ? &r.C : nullptr, &out.f_ext, matrices ? &parts.C : nullptr);
    if (matrices) ScatterBody(r.map, nullptr, &r.M, nullptr, &parts.M);
  }
  return true;
}

Eigen::VectorXd DriveForces(const DofMap& dofs, const Eigen::VectorXd& residual) {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(residual.size());
  for (int j = 0; j < dofs.n_dofs(); ++j)
    if (dofs.prescribed(j)) f[j] = -residual[j];
  return f;
}

}  // namespace dynamic_internal

using namespace dynamic_internal;

namespace dynamic_internal {

Assembly AssembleDynamicResidual(const SystemModel& model, const DofMap& dofs, DynamicState& s, double t,
                                 BodyWorkspace& work, BodyThreads* threads) {
  AssemblyParts parts;
  Assembly out = StartAssembly(model, dofs, parts);
  const int n_bodies = int(model.bodies.size());
  std::vector<BodyPass>& passes = work.passes;
  std::vector<BodyTerms>& results = work.terms;
  passes.resize(static_cast<size_t>(n_bodies));
  results.resize(static_cast<size_t>(n_bodies));
  const std::vector<Eigen::Matrix<double, 6, 1>> node_acc = NodeAccelerations(model, dofs, s.config, s.W, s.Wdot);
  ForEachBody(threads, n_bodies, [&](int b) {
    const SuperelementBody& body = model.bodies[b];
    BodyTerms& r = results[size_t(b)];
    BodyPass& pass = passes[size_t(b)];
    r.frame_ok = true;
    BodyConfiguration& c = pass.data.c;  // evaluated in place: the pass's storage is reused
    BodyConfigurationOf(model, s.config, b, c);
    const FrameSolution frame = body.SolveFrameFrom(c, s.config.frames[b]);
    if (!frame.ok) {
      r.frame_ok = false;
      return;
    }
    s.config.frames[b] = frame;
    body.Evaluate(c, frame, pass.data);
    pass.w = GatherBody(model, dofs, s.config, b, s.W);
    pass.wdot = GatherBodyAcceleration(model, dofs, b, node_acc, s.Wdot);
    // Inertia stiffening (issue 13): K + K_sigma(a), a from this iterate's frame motion; its
    // velocity and acceleration derivatives go into C and M of the iteration matrix.
    const bool stiffening = body.has_inertia_stiffening();
    pass.load = stiffening ? body.InertiaLoads(pass.data, pass.w, pass.wdot, model.gravity) : InertiaLoadFactors{};
    Eigen::VectorXd f_int, f_in, f_acc;
    body.ElasticForce(pass.data, &f_int, nullptr, stiffening ? &pass.load : nullptr);
    body.InertiaForce(pass.data, pass.w, pass.wdot, &f_in, nullptr, nullptr, &f_acc);
    body.AddModalDamping(pass.w, f_in, nullptr);
    r.f_grav.setZero(body.n_coordinates());
    if (model.gravity.squaredNorm() > 0) r.f_grav = body.GravityForce(pass.data, model.gravity);
    // Scale of the forces in balance, each term on its own (for a torque-free body M_g wdot and
    // the gyroscopic terms cancel: their sum is no scale).
    r.scale = std::max({body.ForceNorm(f_int), body.ForceNorm(f_in), body.ForceNorm(r.f_grav), body.force_floor(),
                        body.ForceNorm(f_acc), body.ForceNorm(f_in - f_acc)});
    r.roundoff = body.RoundOffForce(c);
    BodyMap(model, dofs, s.config, b, r.map);
    r.r_b = r.f_grav - f_int - f_in;
  });
  if (!AddBodyTerms(model, results, parts, out)) return out;
  FinishAssembly(model, dofs, s.config, t, s.W, false, parts, out);
  AddLoopConstraints(model, dofs, s.config, &out.residual, nullptr, &out.node_forces);
  return out;
}

void AddDynamicMatrices(const SystemModel& model, const DofMap& dofs, const DynamicState& s, double t,
                        BodyWorkspace& work, bool full_inertia_tangent, Assembly& out,
                        BodyThreads* threads, const MatrixCombination* combine) {
  const int n_bodies = int(model.bodies.size());
  const std::vector<BodyPass>& passes = work.passes;
  std::vector<BodyWorkspace::BodyMatrices>& results = work.matrices;
  results.resize(static_cast<size_t>(n_bodies));
  ForEachBody(threads, n_bodies, [&](int b) {
    const SuperelementBody& body = model.bodies[b];
    const BodyPass& pass = passes[size_t(b)];
    BodyWorkspace::BodyMatrices& r = results[size_t(b)];
    const bool stiffening = body.has_inertia_stiffening();
    Eigen::MatrixXd d_load;
    body.ElasticForce(pass.data, nullptr, &r.K, stiffening ? &pass.load : nullptr, stiffening ? &d_load : nullptr);
    body.InertiaForce(pass.data, pass.w, pass.wdot, nullptr, &r.M, &r.C);
    if (stiffening) {
      r.M.noalias() += d_load * pass.load.d_wdot;
      r.C.noalias() += d_load * pass.load.d_w;
    }
    // Configuration derivative of the inertia force: d(M_g wdot)/dq exactly; that of the
    // quadratic velocity terms by central differences with options.full_inertia_tangent.
    r.K += body.InertiaConfigurationTangent(pass.data, pass.w, pass.wdot, full_inertia_tangent);
    Eigen::VectorXd unused = Eigen::VectorXd::Zero(body.n_coordinates());
    body.AddModalDamping(pass.w, unused, &r.C);
    if (combine) r.K += combine->c_C * r.C + combine->c_M * r.M;
  });
  Triplets &K = work.K, &C = work.C, &M = work.M;
  K.clear();
  C.clear();
  M.clear();
  // The joints' convective accelerations depend on W: d f_in / dW gets M_b dc/dW (the Coriolis
  // and centripetal coupling of chains with offsets), into C (or c_C of it into K).
  // And their configuration: d f_in / dq gets M_b d(J Wdot + c)/dq (into K).
  const bool chains = !model.joints.empty();
  const std::vector<NodeJacobian> dc =
      chains ? ConvectiveVelocityDerivative(model, dofs, s.config, s.W) : std::vector<NodeJacobian>();
  const std::vector<NodeJacobian> dacc =
      chains ? NodeAccelerationConfigurationDerivative(model, dofs, s.config, s.W, s.Wdot) : std::vector<NodeJacobian>();
  // B^T M_b D for a body's node columns D (per node, sparse over the coordinates), scaled.
  const auto add_node_columns = [&](const std::vector<MapEntry>& map, const Eigen::MatrixXd& M_b, int b,
                                    const std::vector<NodeJacobian>& D, double scale, Triplets& into) {
    for (size_t a = 0; a < model.body_nodes[size_t(b)].size(); ++a) {
      for (const auto& [col, v] : D[size_t(model.body_nodes[size_t(b)][a])]) {
        const Eigen::VectorXd y = M_b.middleCols<6>(Eigen::Index(6 * a)) * v;
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
  Eigen::VectorXd unused = Eigen::VectorXd::Zero(n);
  AddNodeLoads(model, s.config, t, unused, &K);
  AddSpringDampers(model, s.config, s.W, unused, &K, &C, nullptr);
  AddLoopConstraints(model, dofs, s.config, nullptr, &K, nullptr);
  AddJointGeometricStiffness(model, dofs, s.config, out.node_forces, K);
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

}  // namespace dynamic_internal

std::vector<Eigen::Matrix<double, 6, 1>> DynamicReactions(const SystemModel& model, const DynamicState& state) {
  const DofMap dofs(model);
  DynamicState s = state;
  const Assembly a = AssembleDynamic(model, dofs, s, s.t, false);
  if (!a.ok) return std::vector<Eigen::Matrix<double, 6, 1>>(model.n_nodes(), Eigen::Matrix<double, 6, 1>::Zero());
  return JointReactions(model, dofs, s.config, a.node_forces);
}

namespace {

// The free accelerations from M_g Wdot = f_ext - f_int - f_gyro at s (prescribed ones as set),
// a = Wdot, and the external and drive forces there: the start of an integration.
void ConsistentAccelerations(const SystemModel& model, const DofMap& dofs, DynamicState& s) {
  const Assembly b = AssembleDynamic(model, dofs, s, s.t, true);
  for (int j : dofs.solved()) s.Wdot[j] = 0.0;
  Eigen::VectorXd rhs = b.residual - b.M * s.Wdot;
  SystemMatrix M = b.M;
  if (dofs.n_multipliers() > 0) {
    // Closed loops: [M G^T; G 0] [Wdot; d lambda] = [r; -Gdot W] (the constraints' second time
    // derivative), with Gdot W = d^2 g / dt^2 along q(t) = q + t W (no coordinate acceleration),
    // by central differences over a step that moves the model by 1e-4 of its size.
    Triplets G;
    AddLoopConstraints(model, dofs, s.config, nullptr, nullptr, nullptr, &G);
    M = b.M + ToMatrix(dofs.n_dofs(), G);
    const double L = std::max(BoundingDiagonal(model.node_x0), 1e-300);
    double speed = 0.0;
    for (int k = 0; k < model.n_nodes(); ++k) speed = std::max(speed, NodeMotion(s.config, k, s.W).head<3>().norm() +
                                                                         L * NodeMotion(s.config, k, s.W).tail<3>().norm());
    if (speed > 0) {
      const double eps = 1e-4 * L / speed;
      const auto g_at = [&](double e) {
        SystemState q = s.config;
        if (e != 0.0) ApplyIncrement(model, dofs, e * s.W, q);
        Eigen::VectorXd r = Eigen::VectorXd::Zero(dofs.n_dofs());
        q.lambda.setZero();
        AddLoopConstraints(model, dofs, q, &r, nullptr, nullptr);
        return Eigen::VectorXd(-r.tail(dofs.n_multipliers()));  // g
      };
      rhs.tail(dofs.n_multipliers()) = -(g_at(eps) - 2 * g_at(0.0) + g_at(-eps)) / (eps * eps);
    } else {
      rhs.tail(dofs.n_multipliers()).setZero();
    }
  }
  const Eigen::VectorXd free_acc = SolveFree(dofs, M, rhs);
  for (int j : dofs.solved()) s.Wdot[j] = free_acc[j];
  if (dofs.n_multipliers() > 0) {
    s.config.lambda += free_acc.tail(dofs.n_multipliers());
    dofs.ClearMultipliers(s.Wdot);
  }
  s.a = s.Wdot;
  s.f_ext = b.f_ext;
  Eigen::VectorXd added = Eigen::VectorXd::Zero(dofs.n_dofs());
  for (int j : dofs.solved()) added[j] = s.Wdot[j];
  s.f_drive = DriveForces(dofs, b.residual - b.M * added);
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

namespace {
// Measure with the bodies' data of the converged iteration at this state (`passes`, one per
// body) or, when empty, evaluated here.
DynamicStepReport MeasureWith(const SystemModel& model, const DofMap& dofs, const DynamicState& s,
                              const std::vector<BodyPass>& passes) {
  DynamicStepReport r;
  r.t = s.t;
  r.external_work = s.external_work;
  Eigen::VectorXd unused = Eigen::VectorXd::Zero(dofs.n_dofs());
  AddSpringDampers(model, s.config, s.W, unused, nullptr, nullptr, &r.elastic_energy);  // spring energy
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    const SuperelementBody& body = model.bodies[b];
    const bool kept = passes.size() == model.bodies.size();
    const SuperelementBody::Data evaluated =
        kept ? SuperelementBody::Data{} : body.Evaluate(BodyConfigurationOf(model, s.config, int(b)), s.config.frames[b]);
    const SuperelementBody::Data& data = kept ? passes[b].data : evaluated;
    const Eigen::VectorXd w = kept ? passes[b].w : BodyVelocityOf(model, dofs, s, int(b));
    r.kinetic_energy += body.KineticEnergy(data, w);
    r.elastic_energy += body.ElasticEnergy(data);
    Eigen::Vector3d L, H;
    body.Momentum(data, w, &L, &H);
    r.linear_momentum += L;
    r.angular_momentum += H;
  }
  return r;
}
}  // namespace

DynamicStepReport Measure(const SystemModel& model, DynamicState& s) {
  return MeasureWith(model, DofMap(model), s, {});
}

namespace {

// One generalized-alpha step of size h from `state` into `next` (Arnold & Bruls 2007).
// t_new: the time reached, state.t + h, or just below a breakpoint the step lands on (the loads
// and drives there are their left limits).
StepOutcome GeneralizedAlphaStep(const SystemModel& model, const DofMap& dofs, const DynamicOptions& options,
                                 const DynamicState& state, double h, double t_new, IterationMatrix& matrix,
                                 BodyThreads& threads, BodyWorkspace& work, DynamicState& next) {
  const double rho = std::clamp(options.rho_inf, 0.0, 1.0);
  const double alpha_m = (2 * rho - 1) / (rho + 1), alpha_f = rho / (rho + 1);
  const double gamma = 0.5 + alpha_f - alpha_m, beta = 0.25 * (gamma + 0.5) * (gamma + 0.5);
  next = state;
  const Eigen::VectorXd a_pred = (alpha_f * state.Wdot - alpha_m * state.a) / (1 - alpha_m);
  next.a = a_pred;
  next.Wdot.setZero();
  next.W = state.W + h * (1 - gamma) * state.a + h * gamma * a_pred;
  const Eigen::VectorXd dq = state.W + h * (0.5 - beta) * state.a + h * beta * a_pred;
  ApplyIncrement(model, dofs, h * dq, next.config);
  ApplyPrescribed(model, dofs, t_new, next.config, &next.W, &next.Wdot);
  const double gamma_p = gamma / (beta * h), beta_p = (1 - alpha_m) / (beta * h * h * (1 - alpha_f));
  StepOutcome out;
  const double tolerance = std::max(options.tolerance, kRoundOffTolerance);
  const Eigen::VectorXd weights = ResidualWeights(model, dofs);
  DivergenceTest divergence;
  // Closed loops: the constraints hold to the tolerance times the model's size.

  for (; out.iterations < options.max_iterations; ++out.iterations) {
    Assembly a = AssembleDynamicResidual(model, dofs, next, t_new, work, &threads);
    if (!a.ok || !a.residual.allFinite()) return out;
    const double r_norm = FreeNorm(dofs, a.residual, weights);
    if (r_norm <= std::max(tolerance * a.scale, a.roundoff) && out.iterations > 0 &&
        LoopsClosed(model, next.config, tolerance)) {
      out.converged = true;
      next.a += (1 - alpha_f) / (1 - alpha_m) * next.Wdot;
      next.t = t_new;
      // External work by the trapezoidal rule on the increment h (W_n + W_n+1) / 2.
      next.external_work += 0.5 * (state.f_ext + a.f_ext).dot(h * 0.5 * (state.W + next.W));
      next.f_ext = a.f_ext;
      next.f_drive = DriveForces(dofs, a.residual);
      next.drive_work += 0.5 * (state.f_drive + next.f_drive).dot(h * 0.5 * (state.W + next.W));
      out.passes_kept = true;
      return out;
    }
    if (divergence.Diverged(out.iterations, r_norm)) return out;
    bool built = false;
    const auto S = [&] {
      const MatrixCombination combine{gamma_p, beta_p};
      if (!built) AddDynamicMatrices(model, dofs, next, t_new, work, options.full_inertia_tangent, a, &threads, &combine);
      built = true;
      return a.K;  // K + gamma' C + beta' M
    };
    Eigen::VectorXd delta;
    if (!matrix.Increment(dofs, options, h, S, a.residual, delta, out.singular_matrix)) return out;
    ApplyIncrement(model, dofs, delta, next.config);
    next.W += gamma_p * delta;
    next.Wdot += beta_p * delta;
    dofs.ClearMultipliers(next.W);  // the multipliers took their increment in next.config
    dofs.ClearMultipliers(next.Wdot);
  }
  return out;
}

}  // namespace

DynamicResult SolveDynamic(const SystemModel& model, DynamicState& state, const DynamicOptions& options,
                           const std::function<void(const DynamicStepReport&, const DynamicState&)>& on_step) {
  DynamicResult result;
  const DofMap dofs(model);
  const std::vector<RotationNode> triples = RotationNodes(model, dofs);
  StepController control(model, dofs, options, state.t);
  double h = options.adaptive ? control.FirstStep() : options.step;
  int cuts = 0;
  bool after_rejection = false;
  IterationMatrix matrix;
  BodyThreads threads(options.threads);
  BodyWorkspace work;
  // Time is counted in steps: t = t_base + n h while the step stays nominal (summing h over 1e6
  // steps drifted by 1e-8 s and left a last step of 1e-8 s that Newton could not take), and a
  // remainder below 1% of a step is merged into the last one.
  double t_base = state.t;
  long n_nominal = 0;
  const double t_output0 = state.t;
  double last_output = 0;
  // Energy balance E = T + U - W_loads - W_drives: constant for a conservative system, falling
  // with damping (modal, dampers, generalized-alpha's rho_inf < 1). Growth is numerical: a step
  // too long for the stiffest modes (generalized-alpha with rho_inf near 1 on stiff modes; the
  // midpoint scheme's elastic force is not an exact discrete gradient). Above 5% of the energy
  // scale (the largest of T + U and the works so far) it is said once; above 25% the run stops.
  constexpr double kEnergyWarn = 0.05, kEnergyStop = 0.25;
  const DynamicStepReport start = Measure(model, state);
  const double E0 = start.kinetic_energy + start.elastic_energy;
  double energy_scale = std::abs(E0);
  bool warned = false;
  if (const std::string w = RoundOffToleranceWarning(options.tolerance); !w.empty()) result.warnings.push_back(w);
  const auto count_factorizations = [&] {
    result.factorizations = matrix.factorizations;
    result.pattern_analyses = matrix.solver.analyses();
    result.pivoted = matrix.solver.full_factorizations();
  };
  auto fail = [&](const std::string& message) {
    result.message = message;
    if (const std::string why = LoopSingularity(model, state.config); !why.empty()) result.message += "; " + why;
    count_factorizations();
    return result;
  };
  while (state.t < options.end_time - 1e-12 * std::max(std::abs(options.end_time), options.step)) {
    if (options.adaptive) {
      h = control.Fit(state.t, h);
    } else {
      const double remaining = options.end_time - state.t;
      if (remaining <= 1.01 * h) h = remaining;
    }
    DynamicState next;
    matrix.with_this_factor = 0;  // a step may use the kept factor for reuse_max_iterations iterations
    const double t_new =
        options.adaptive && control.at_breakpoint() ? std::nextafter(control.boundary(), -HUGE_VAL) : state.t + h;
    const StepOutcome step =
        options.integrator == Integrator::kMidpoint
            ? MidpointStep(model, dofs, options, triples, state, h, t_new, matrix, threads, next)
            : GeneralizedAlphaStep(model, dofs, options, state, h, t_new, matrix, threads, work, next);
    if (!step.converged && result.steps == 0 && result.newton_cuts == 0 && step.singular_matrix.size() > 0) {
      // The first iteration matrix is singular: the model's, not the step's.
      const std::string why = DescribeSingular(model, dofs, state.config, step.singular_matrix);
      if (!why.empty()) {
        result.message = "iteration matrix at the start: " + why;
        return result;
      }
    }
    if (!step.converged && options.adaptive) {
      matrix.solver.Invalidate();
      ++result.newton_cuts;
      after_rejection = true;
      if (0.5 * h < control.min_step()) {
        char buffer[200];
        std::snprintf(buffer, sizeof buffer, "Newton diverged at t = %.6g with step %.3g (min_step %.3g)", state.t, h,
                      control.min_step());
        return fail(buffer);
      }
      h *= 0.5;
      continue;
    }
    double error = 0.0;
    if (options.adaptive) {
      error = control.Error(state, next, h);
      if (error > 1.0) {
        ++result.rejected_by_error;
        after_rejection = true;
        const double h_new = h * StepController::Factor(error);
        if (h_new < control.min_step()) {
          char buffer[300];
          std::snprintf(buffer, sizeof buffer,
                        "the step fell below min_step %.3g at t = %.6g (estimated local error %.3g times "
                        "step_tolerance with step %.3g)",
                        control.min_step(), state.t, error, h);
          return fail(buffer);
        }
        h = h_new;
        continue;
      }
      next.t = control.lands() ? control.boundary() : state.t + h;
    }
    if (!step.converged) {
      matrix.solver.Invalidate();
      ++result.newton_cuts;
      if (cuts >= options.max_cuts) {
        char buffer[200];
        std::snprintf(buffer, sizeof buffer, "Newton diverged at t = %.6g after %d step cuts (step %.3g)",
                      state.t, cuts, h);
        return fail(buffer);
      }
      h *= 0.5;
      ++cuts;
      continue;
    }
    bool output = true;
    if (options.adaptive) {
      output = control.output();
    } else {
      if (h == options.step) {
        next.t = t_base + double(++n_nominal) * options.step;
      } else {
        t_base = next.t;
        n_nominal = 0;
      }
      if (options.end_time - next.t < 1e-9 * h) next.t = options.end_time;
      if (options.output_step > 0) {
        // The first step at or after each output time.
        const double k = std::floor((next.t - t_output0) / options.output_step + 1e-9);
        output = k > last_output || next.t >= options.end_time;
        if (output) last_output = k;
      }
    }
    next.h_last = h;
    state = next;
    if (options.adaptive && control.at_breakpoint()) {
      // A load or drive jumps or kinks here: restart from the state with the accelerations of the
      // right limit (as at the start), so no step sees the jump inside it.
      ApplyPrescribed(model, dofs, state.t, state.config, &state.W, &state.Wdot);
      ConsistentAccelerations(model, dofs, state);
      state.h_last = 0.0;
    }
    result.steps += 1;
    result.newton_iterations += step.iterations;
    static const std::vector<BodyPass> kNone;
    DynamicStepReport r = MeasureWith(model, dofs, state, step.passes_kept ? work.passes : kNone);
    r.h = h;
    r.iterations = step.iterations;
    r.rejected = result.rejected_by_error + result.newton_cuts;
    r.output = output;
    if (on_step) on_step(r, state);
    const double energy = r.kinetic_energy + r.elastic_energy;
    energy_scale = std::max({energy_scale, std::abs(energy), std::abs(state.external_work), std::abs(state.drive_work)});
    const double growth = energy - state.external_work - state.drive_work - E0;
    // Judged from the 10th step on: over the first few steps of a smooth start (a spin-up
    // drive, energy ~ t^6) the trapezoidal work of the drives is off by tens of percent of an
    // energy that is itself round-off (a one-body spin-up stopped at t = 0.01 with 2.4e-16 J of
    // 4.1e-16 J); the rule's error falls as 1/n^2 of the steps taken.
    if (result.steps >= 10 && energy_scale > 0 && growth > kEnergyWarn * energy_scale) {
      char buffer[400];
      std::snprintf(buffer, sizeof buffer,
                    "the energy grew by %.3g (%.1f%% of %.3g) at t = %.6g beyond the work of the loads and drives: "
                    "numerically unstable at step %.3g; reduce analysis.%s%s",
                    growth, 100 * growth / energy_scale, energy_scale, state.t, h,
                    options.adaptive ? "step_tolerance" : "step",
                    options.integrator == Integrator::kGeneralizedAlpha ? " or analysis.rho_inf" : "");
      if (growth > kEnergyStop * energy_scale) return fail(buffer);
      if (!warned) result.warnings.push_back(buffer);
      warned = true;
    }
    if (options.adaptive) {
      h = control.Accept(state, h, error, after_rejection);
      after_rejection = false;
    } else if (cuts > 0 && step.iterations <= 4) {
      h = std::min(options.step, 2 * h);
      --cuts;
    }
  }
  count_factorizations();
  result.ok = true;
  return result;
}

}  // namespace femb
