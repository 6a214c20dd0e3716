#include "solver/assembly/system.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "solver/assembly/body_pass.h"
#include "solver/rotation.h"

namespace femb {

std::vector<MapEntry> BodyMap(const SystemModel& model, const DofMap& dofs, const SystemState& state, int b) {
  std::vector<MapEntry> map;
  BodyMap(model, dofs, state, b, map);
  return map;
}

void BodyMap(const SystemModel& model, const DofMap& dofs, const SystemState& state, int b,
             std::vector<MapEntry>& map) {
  const SuperelementBody& body = model.bodies[b];
  map.clear();
  for (int a = 0; a < body.n_nodes(); ++a) {
    const int k = model.body_nodes[b][a];
    for (const auto& [col, vec] : state.J[k]) {
      for (int i = 0; i < 6; ++i) {
        if (vec[i] != 0.0) map.push_back({6 * a + i, col, vec[i]});
      }
    }
  }
  for (int m = 0; m < body.n_modes(); ++m) map.push_back({6 * body.n_nodes() + m, dofs.mode_dof(b) + m, 1.0});
}

void ScatterBody(const std::vector<MapEntry>& map, const Eigen::VectorXd* f, const Eigen::MatrixXd* K,
                 Eigen::VectorXd* F, Triplets* KK) {
  for (const MapEntry& a : map) {
    if (f && F) (*F)[a.coordinate] += a.coefficient * (*f)[a.local];
    if (!K || !KK) continue;
    for (const MapEntry& b : map) {
      const double v = a.coefficient * b.coefficient * (*K)(a.local, b.local);
      if (v != 0.0) KK->emplace_back(a.coordinate, b.coordinate, v);
    }
  }
}

SystemMatrix ToMatrix(int n, const Triplets& triplets) {
  SystemMatrix A(n, n);
  A.setFromTriplets(triplets.begin(), triplets.end());
  return A;
}

const SystemMatrix& TripletAssembler::Build(int n, const Triplets& triplets) {
  const size_t m = triplets.size();
  bool same = matrix_.rows() == n && rows_.size() == m;
  for (size_t i = 0; same && i < m; ++i) same = triplets[i].row() == rows_[i] && triplets[i].col() == cols_[i];
  if (!same) {
    matrix_ = ToMatrix(n, triplets);
    ++rebuilds_;
    rows_.resize(m);
    cols_.resize(m);
    slots_.resize(m);
    const int* outer = matrix_.outerIndexPtr();
    const int* inner = matrix_.innerIndexPtr();
    for (size_t i = 0; i < m; ++i) {
      rows_[i] = triplets[i].row();
      cols_[i] = triplets[i].col();
      const int* found = std::lower_bound(inner + outer[cols_[i]], inner + outer[cols_[i] + 1], rows_[i]);
      slots_[i] = int(found - inner);
    }
    return matrix_;
  }
  double* values = matrix_.valuePtr();
  std::fill(values, values + matrix_.nonZeros(), 0.0);
  for (size_t i = 0; i < m; ++i) values[slots_[i]] += triplets[i].value();
  return matrix_;
}

Eigen::VectorXd GatherBody(const SystemModel& model, const DofMap& dofs, const SystemState& state, int b,
                           const Eigen::VectorXd& W) {
  Eigen::VectorXd w;
  GatherBody(model, dofs, state, b, W, w);
  return w;
}

void GatherBody(const SystemModel& model, const DofMap& dofs, const SystemState& state, int b, const Eigen::VectorXd& W,
                Eigen::VectorXd& w) {
  const SuperelementBody& body = model.bodies[b];
  w.resize(body.n_coordinates());
  for (int a = 0; a < body.n_nodes(); ++a) w.segment<6>(6 * a) = NodeMotion(state, model.body_nodes[b][a], W);
  w.tail(body.n_modes()) = W.segment(dofs.mode_dof(b), body.n_modes());
}

Eigen::VectorXd GatherBodyAcceleration(const SystemModel& model, const DofMap& dofs, int b,
                                       const std::vector<Eigen::Matrix<double, 6, 1>>& node_acc,
                                       const Eigen::VectorXd& Wdot) {
  Eigen::VectorXd w;
  GatherBodyAcceleration(model, dofs, b, node_acc, Wdot, w);
  return w;
}

void GatherBodyAcceleration(const SystemModel& model, const DofMap& dofs, int b,
                            const std::vector<Eigen::Matrix<double, 6, 1>>& node_acc, const Eigen::VectorXd& Wdot,
                            Eigen::VectorXd& w) {
  const SuperelementBody& body = model.bodies[b];
  w.resize(body.n_coordinates());
  for (int a = 0; a < body.n_nodes(); ++a) w.segment<6>(6 * a) = node_acc[model.body_nodes[b][a]];
  w.tail(body.n_modes()) = Wdot.segment(dofs.mode_dof(b), body.n_modes());
}

void AddBodyNodeForces(const SystemModel& model, int b, const Eigen::VectorXd& r_b, NodeForces& forces) {
  for (size_t a = 0; a < model.body_nodes[b].size(); ++a) {
    forces.Add(model.body_nodes[b][a], r_b.segment<6>(6 * a));
  }
}

namespace {

// The bodies' static terms added in body order: the internal forces (and tangents) into the
// residual, their weight into `gravity` (the loads', for the force scale). False (the message in
// `out`) when a body's floating frame did not converge.
bool AddStaticBodyTerms(const SystemModel& model, bool with_tangent, bool gravity_on, StaticWorkspace& work,
                        SystemForces& out) {
  for (size_t b = 0; b < work.terms.size(); ++b) {
    const BodyTerms& r = work.terms[b];
    if (!r.frame_ok) {
      out.ok = false;
      out.message = "floating frame of body " + std::to_string(b) + " did not converge";
      return false;
    }
    out.elastic_energy += r.elastic_energy;
    out.force_scale = std::max(out.force_scale, r.scale);
    out.roundoff += r.roundoff;
    AddBodyScale(r.map, r.scale, out.dof_scale);
    ScatterBody(r.map, &r.r_b, with_tangent ? &r.K : nullptr, &out.residual, with_tangent ? &work.parts.K : nullptr);
    AddBodyNodeForces(model, int(b), r.r_b, work.parts.node_forces);
    if (gravity_on) {
      ScatterBody(r.map, &r.f_grav, nullptr, &work.gravity, nullptr);
      AddBodyNodeForces(model, int(b), r.f_grav, work.parts.node_forces);
    }
  }
  return true;
}

}  // namespace

SystemForces AssembleStatic(const SystemModel& model, const DofMap& dofs, SystemState& state, double lambda,
                            bool with_tangent, StaticWorkspace* workspace, BodyThreads* threads) {
  StaticWorkspace own;
  StaticWorkspace& work = workspace ? *workspace : own;
  SystemForces out;
  const int n = dofs.n_dofs();
  out.residual = Eigen::VectorXd::Zero(n);
  out.dof_scale = Eigen::VectorXd::Zero(n);
  AssemblyParts& parts = work.parts;
  Triplets* tangent = with_tangent ? &parts.K : nullptr;
  parts.K.clear();
  parts.node_forces.f.assign(size_t(model.n_nodes()), Eigen::Matrix<double, 6, 1>::Zero());
  work.gravity.setZero(n);
  // Gravity in a static analysis, ramped to full at pseudo-time static_gravity_end; the stress of
  // the body's own weight stiffens it (load factors -R_j^T g at rest).
  const bool gravity_on = model.static_gravity_end > 0 && model.gravity.squaredNorm() > 0;
  const double ramp = gravity_on ? std::min(lambda / model.static_gravity_end, 1.0) : 0.0;
  BodyPassKind kind;
  kind.at_rest = true;
  kind.elastic_tangent = with_tangent;
  kind.gravity = ramp * model.gravity;
  const int n_bodies = int(model.bodies.size());
  work.passes.resize(size_t(n_bodies));
  work.terms.resize(size_t(n_bodies));
  ForEachBody(threads, n_bodies, [&](int b) {
    BodyPass& pass = work.passes[size_t(b)];
    pass.w.setZero(model.bodies[b].n_coordinates());
    pass.wdot.setZero(model.bodies[b].n_coordinates());
    EvaluateBodyTerms(model, dofs, state, b, kind, pass, work.terms[size_t(b)]);
  });
  if (!AddStaticBodyTerms(model, with_tangent, gravity_on, work, out)) return out;
  NodeForces& node_forces = parts.node_forces;
  Eigen::VectorXd& loads = parts.loads;
  loads.setZero(n);
  AddNodeLoads(model, state, lambda, loads, tangent, &node_forces);
  AddUserForces(model, state, Eigen::VectorXd(), lambda, &loads, tangent, nullptr, &node_forces);
  loads += work.gravity;
  out.loads = loads;
  AddSpringDampers(model, state, Eigen::VectorXd(), &loads, tangent, nullptr, &out.elastic_energy, &node_forces,
                   &parts.scratch);
  out.residual += loads;
  ResidualWeights(model, dofs, parts.weights);
  const double applied = (parts.weights.asDiagonal() * loads).norm();
  out.force_scale = std::max(out.force_scale, applied);
  FinishDofScale(applied, std::max(out.force_scale, 1e-300), out.dof_scale);
  AddLoopConstraints(model, dofs, state, &out.residual, tangent, &node_forces);
  out.node_forces = node_forces;
  if (with_tangent) {
    AddJointGeometricStiffness(model, dofs, state, node_forces, parts.K);
    out.tangent = work.tangent.Build(n, parts.K);
  }
  return out;
}

void AddNodeLoads(const SystemModel& model, const SystemState& state, double t, Eigen::VectorXd& residual,
                  Triplets* tangent, NodeForces* node_forces) {
  for (const NodeLoad& load : model.loads) {
    const NodeJacobian& J = state.J[load.node];
    if (J.empty()) continue;  // clamped: the support takes it
    const double s = load.Scale(t);
    const Eigen::Matrix3d& R = state.R[load.node];
    const Eigen::Vector3d F = s * (load.follower ? Eigen::Vector3d(R * load.force) : load.force);
    const Eigen::Vector3d Mo = s * (load.follower ? Eigen::Vector3d(R * load.moment) : load.moment);
    Eigen::Matrix<double, 6, 1> f;
    f << F, Mo;
    if (node_forces) node_forces->Add(load.node, f);
    for (const auto& [col, vec] : J) residual[col] += vec.dot(f);
    if (tangent && load.follower) {
      // d(R F_loc)/d pi = -(R F_loc)~: enters the tangent of f_int - f_ext with a plus sign.
      Eigen::Matrix<double, 6, 6> K = Eigen::Matrix<double, 6, 6>::Zero();
      K.block<3, 3>(0, 3) = Skew<double>(F);
      K.block<3, 3>(3, 3) = Skew<double>(Mo);
      for (const auto& [ci, vi] : J) {
        for (const auto& [cj, vj] : J) tangent->emplace_back(ci, cj, vi.dot(K * vj));
      }
    }
  }
}

void AddSpringDampers(const SystemModel& model, const SystemState& state, const Eigen::VectorXd& W,
                      Eigen::VectorXd* residual, Triplets* K, Triplets* C, double* energy, NodeForces* node_forces,
                      SystemScratch* scratch) {
  SystemScratch own;
  SystemScratch& work = scratch ? *scratch : own;
  std::vector<MapEntry>& map = work.map;  // the 6 translational components (a, b) -> coordinates
  Eigen::VectorXd& fv = work.fv;
  Eigen::MatrixXd &Km = work.Km, &Cm = work.Cm;
  for (const SpringDamper& s : model.springs) {
    Eigen::Vector3d x[2], v[2];
    const int nodes[2] = {s.node_a, s.node_b};
    map.clear();
    for (int e = 0; e < 2; ++e) {
      const int k = nodes[e];
      x[e] = k >= 0 ? state.x[k] : s.ground;
      v[e] = k >= 0 ? Eigen::Vector3d(NodeMotion(state, k, W).head<3>()) : Eigen::Vector3d::Zero();
      if (k < 0) continue;
      for (const auto& [col, vec] : state.J[k]) {
        for (int i = 0; i < 3; ++i) {
          if (vec[i] != 0.0) map.push_back({3 * e + i, col, vec[i]});
        }
      }
    }
    const SpringDamperForces f = EvaluateSpringDamper(s, x[0], x[1], v[0], v[1]);
    if (energy) *energy += f.energy;
    if (node_forces) {
      for (int e = 0; e < 2; ++e) {
        if (nodes[e] < 0) continue;
        Eigen::Matrix<double, 6, 1> fe = Eigen::Matrix<double, 6, 1>::Zero();
        fe.head<3>() = f.f.segment<3>(3 * e);
        node_forces->Add(nodes[e], fe);
      }
    }
    fv = f.f;
    Km = f.K;
    Cm = f.C;
    ScatterBody(map, &fv, K ? &Km : nullptr, residual, K);
    if (C) ScatterBody(map, nullptr, &Cm, nullptr, C);
  }
}

Eigen::VectorXd ResidualWeights(const SystemModel& model, const DofMap& dofs) {
  Eigen::VectorXd w;
  ResidualWeights(model, dofs, w);
  return w;
}

void ResidualWeights(const SystemModel& model, const DofMap& dofs, Eigen::VectorXd& w) {
  const double L = ModelSize(model);
  w.setOnes(dofs.n_dofs());
  for (int k = 0; k < model.n_nodes(); ++k) {
    const int first = dofs.node_first(k), j = dofs.joint_of(k);
    if (j < 0) {
      w.segment<3>(first + 3).setConstant(1.0 / L);  // a free node's rotation increments
      continue;
    }
    const NodeJoint& joint = model.joints[j];
    for (int c = 0; c < joint.n_coordinates(); ++c) {
      if (c != joint.s_index()) w[first + c] = 1.0 / L;  // every joint coordinate but a travel is an angle
    }
  }
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    const int m = model.bodies[b].n_modes();
    if (m > 0) w.segment(dofs.mode_dof(int(b)), m).setConstant(model.bodies[b].ModalForceWeight());
  }
  // The multipliers' rows hold constraint violations, not forces: LoopViolation judges them.
  if (dofs.n_multipliers() > 0) w.tail(dofs.n_multipliers()).setZero();
}

double ScaledFreeNorm(const DofMap& dofs, const Eigen::VectorXd& r, const Eigen::VectorXd& weights,
                      const Eigen::VectorXd& scale) {
  double s = 0;
  for (int j : dofs.solved()) {
    const double x = weights[j] * r[j] / scale[j];
    s += x * x;
  }
  return std::sqrt(s);
}

void AddBodyScale(const std::vector<MapEntry>& map, double scale, Eigen::VectorXd& dof_scale) {
  for (const MapEntry& e : map)
    if (e.coefficient != 0.0) dof_scale[e.coordinate] = std::max(dof_scale[e.coordinate], scale);
}

void FinishDofScale(double applied, double whole, Eigen::VectorXd& dof_scale) {
  for (Eigen::Index j = 0; j < dof_scale.size(); ++j)
    dof_scale[j] = dof_scale[j] > 0.0 ? std::max(dof_scale[j], applied) : whole;
}

double FreeNorm(const DofMap& dofs, const Eigen::VectorXd& r, const Eigen::VectorXd& weights) {
  double s = 0;
  for (int j : dofs.solved()) s += weights[j] * weights[j] * r[j] * r[j];
  return std::sqrt(s);
}

}  // namespace femb
