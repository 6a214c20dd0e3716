#include "solver/assembly/body_pass.h"

#include <algorithm>

namespace femb {

void StartAssembly(const SystemModel& model, const DofMap& dofs, AssemblyParts& parts, Assembly& out) {
  out.ok = true;
  out.message.clear();
  out.residual.setZero(dofs.n_dofs());
  out.f_ext.setZero(dofs.n_dofs());
  out.scale = 0.0;
  out.dof_scale.setZero(dofs.n_dofs());
  out.roundoff = 0.0;
  parts.K.clear();
  parts.C.clear();
  parts.M.clear();
  parts.node_forces.f.assign(size_t(model.n_nodes()), Eigen::Matrix<double, 6, 1>::Zero());
}

void FinishAssembly(const SystemModel& model, const DofMap& dofs, const SystemState& config, double t,
                    const Eigen::VectorXd& W, bool matrices, AssemblyParts& parts, Assembly& out) {
  Eigen::VectorXd &loads = parts.loads, &springs = parts.springs, &weights = parts.weights;
  const int n = dofs.n_dofs();
  loads.setZero(n);
  AddNodeLoads(model, config, t, loads, matrices ? &parts.K : nullptr, &parts.node_forces);
  AddUserForces(model, config, W, t, &loads, matrices ? &parts.K : nullptr, matrices ? &parts.C : nullptr,
                &parts.node_forces);
  out.residual += loads;
  out.f_ext += loads;
  springs.setZero(n);
  AddSpringDampers(model, config, W, &springs, matrices ? &parts.K : nullptr, matrices ? &parts.C : nullptr, nullptr,
                   &parts.node_forces, &parts.scratch);
  out.residual += springs;
  if (matrices) AddJointGeometricStiffness(model, dofs, config, parts.node_forces, parts.K, &parts.scratch);
  ResidualWeights(model, dofs, weights);
  const double applied = std::max((weights.asDiagonal() * springs).norm(), (weights.asDiagonal() * loads).norm());
  out.scale = std::max({out.scale, applied, 1e-300});
  FinishDofScale(applied, out.scale, out.dof_scale);
  out.node_forces.f = parts.node_forces.f;
}

namespace {

// The body's weight (GravityForce), or zeros without gravity.
void Weight(const SuperelementBody& body, const BodyPassKind& kind, BodyPass& pass, BodyTerms& r) {
  if (kind.gravity.squaredNorm() > 0) {
    GravityForce(body, pass.data, kind.gravity, r.f_grav);
  } else {
    r.f_grav.setZero(body.n_coordinates());
  }
}

// At rest: the internal force and, for statics' tangent, its stiffness less the weight's
// configuration derivative (S = -dr/dq: minus GravityTangent); the elastic energy; the weight.
void BodyTermsAtRest(const SuperelementBody& body, const BodyPassKind& kind, BodyPass& pass, BodyTerms& r) {
  const bool weight = kind.gravity.squaredNorm() > 0;
  StiffenedElasticForce(body, pass.data, pass.w, pass.wdot, kind.gravity, pass.load, r.f_int,
                        kind.elastic_tangent ? &r.K : nullptr);
  r.elastic_energy = ElasticEnergy(body, pass.data);
  r.scale = std::max(body.ForceNorm(r.f_int), body.force_floor());
  r.roundoff = RoundOffForce(body, pass.data.c, kind.inertia_factor);
  if (kind.elastic_tangent && weight) r.K -= GravityTangent(body, pass.data, kind.gravity);
  r.r_b = -r.f_int;
  Weight(body, kind, pass, r);
}

// In motion: the stiffened internal force, the inertia force with modal damping, the weight.
void BodyTermsInMotion(const SuperelementBody& body, const BodyPassKind& kind, BodyPass& pass, BodyTerms& r) {
  // Inertia stiffening: K + K_sigma(a), a from this iterate's frame motion; its velocity and
  // acceleration derivatives go into C and M of the iteration matrix.
  Eigen::VectorXd &f_int = r.f_int, &f_in = r.f_in, &f_acc = r.f_acc;
  StiffenedElasticForce(body, pass.data, pass.w, pass.wdot, kind.gravity, pass.load, f_int);
  InertiaForce(body, pass.data, pass.w, pass.wdot, &f_in, nullptr, nullptr, &f_acc);
  AddModalDamping(body, pass.w, f_in, nullptr);
  Weight(body, kind, pass, r);
  // Scale of the forces in balance, each term on its own (for a torque-free body M_g wdot and
  // the gyroscopic terms cancel: their sum is no scale).
  r.f_quadratic = f_in - f_acc;
  r.scale = std::max({body.ForceNorm(f_int), body.ForceNorm(f_in), body.ForceNorm(r.f_grav), body.force_floor(),
                      body.ForceNorm(f_acc), body.ForceNorm(r.f_quadratic)});
  r.roundoff = RoundOffForce(body, pass.data.c, kind.inertia_factor);
  r.r_b = r.f_grav - f_int - f_in;
}

}  // namespace

void EvaluateBodyTerms(const SystemModel& model, const DofMap& dofs, SystemState& config, int b,
                       const BodyPassKind& kind, BodyPass& pass, BodyTerms& r) {
  const SuperelementBody& body = model.bodies[b];
  r.frame_ok = true;
  BodyConfigurationOf(model, config, b, pass.data.c);  // evaluated in place: the pass's storage is reused
  // The frame from the last one (warm: iterating with the last pass's S^-1, the same body a
  // Newton correction or a step earlier).
  const FrameSolution frame = PlaceBody(body, config.frames[b], pass.data, kind.warm_frame);
  if (!frame.ok) {
    r.frame_ok = false;
    return;
  }
  config.frames[b] = frame;
  if (kind.at_rest) {
    BodyTermsAtRest(body, kind, pass, r);
  } else {
    BodyTermsInMotion(body, kind, pass, r);
  }
  BodyMap(model, dofs, config, b, r.map);
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
    AddBodyScale(r.map, r.scale, out.dof_scale);
    out.roundoff += r.roundoff;
    AddBodyNodeForces(model, int(b), r.r_b, parts.node_forces);
    ScatterBody(r.map, &r.r_b, nullptr, &out.residual, nullptr);
    ScatterBody(r.map, &r.f_grav, nullptr, &out.f_ext, nullptr);
  }
  return true;
}

}  // namespace femb
