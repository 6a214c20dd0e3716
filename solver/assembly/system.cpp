#include "solver/assembly/system.h"

#include <klu.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "formats/input_error.h"
#include "solver/rotation.h"

namespace femb {

DofMap::DofMap(const SystemModel& model) : motion_(&model.motion) {
  const int n = model.n_nodes();
  joint_of_.assign(n, -1);
  for (size_t j = 0; j < model.joints.size(); ++j) {
    const int c = model.joints[j].child;
    if (joint_of_[c] >= 0) {
      throw InputError("node '" + model.node_names[c] + "' has two parent joints");
    }
    joint_of_[c] = int(j);
  }
  // Parents before children; a node met again on its own parent chain closes a cycle.
  std::vector<int> state(n, 0);  // 0 new, 1 on the chain, 2 placed
  for (int k = 0; k < n; ++k) {
    std::vector<int> chain;
    int m = k;
    while (m >= 0 && state[m] == 0) {
      state[m] = 1;
      chain.push_back(m);
      m = joint_of_[m] >= 0 ? model.joints[joint_of_[m]].parent : -1;
    }
    if (m >= 0 && state[m] == 1) {
      std::string names;
      for (int c : chain) names += (names.empty() ? "" : " -> ") + model.node_names[c];
      throw InputError("joint dependency cycle through nodes " + names + " -> " + model.node_names[m]);
    }
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
      state[*it] = 2;
      order_.push_back(*it);
    }
  }
  for (int k = 0; k < n; ++k) {
    node_first_.push_back(n_dofs_);
    node_count_.push_back(joint_of_[k] >= 0 ? model.joints[joint_of_[k]].n_coordinates() : int(model.motion[k].cols()));
    n_dofs_ += node_count_.back();
  }
  for (const SuperelementBody& body : model.bodies) {
    mode_dof_.push_back(n_dofs_);
    n_dofs_ += body.n_modes();
  }
  first_multiplier_ = n_dofs_;
  for (const CutJoint& cut : model.cut_joints) {
    multiplier_first_.push_back(n_dofs_);
    n_dofs_ += int(cut.equations.size());
  }
  prescribed_.assign(n_dofs_, false);
  for (const auto& p : model.prescribed) prescribed_[prescribed_index(p)] = true;
  for (int j = 0; j < n_dofs_; ++j) {
    if (!prescribed_[j]) solved_.push_back(j);
  }
}

Eigen::Matrix<double, 6, 1> NodeMotion(const SystemState& state, int k, const Eigen::VectorXd& dz) {
  Eigen::Matrix<double, 6, 1> v = Eigen::Matrix<double, 6, 1>::Zero();
  if (dz.size() == 0) return v;
  for (const auto& [col, vec] : state.J[k]) v += vec * dz[col];
  return v;
}

void UpdateKinematics(const SystemModel& model, const DofMap& dofs, SystemState& state) {
  state.J.assign(model.n_nodes(), NodeJacobian());
  for (int k : dofs.order()) {
    const int j = dofs.joint_of(k);
    NodeJacobian& J = state.J[k];
    if (j < 0) {
      const Eigen::MatrixXd& S = dofs.S(k);
      for (int c = 0; c < S.cols(); ++c) J.emplace_back(dofs.node_first(k) + c, S.col(c));
      continue;
    }
    const NodeJoint& joint = model.joints[j];
    const int p = joint.parent;
    PlaceChild(joint, state.x[p], state.R[p], state.z[k], &state.x[k], &state.R[k]);
    const JointMaps maps = ComputeJointMaps(joint, state.x[p], state.R[p], state.x[k], state.z[k]);
    for (const auto& [col, vec] : state.J[p]) {
      const Eigen::Matrix<double, 6, 1> v = maps.A * vec;
      if (v.squaredNorm() > 0) J.emplace_back(col, v);
    }
    for (int c = 0; c < joint.n_coordinates(); ++c) J.emplace_back(dofs.node_first(k) + c, maps.B.col(c));
  }
}

std::vector<Eigen::Matrix<double, 6, 1>> NodeAccelerations(const SystemModel& model, const DofMap& dofs,
                                                           const SystemState& state, const Eigen::VectorXd& W,
                                                           const Eigen::VectorXd& Wdot) {
  std::vector<Eigen::Matrix<double, 6, 1>> acc(model.n_nodes(), Eigen::Matrix<double, 6, 1>::Zero());
  std::vector<Eigen::Matrix<double, 6, 1>> convective(model.n_nodes(), Eigen::Matrix<double, 6, 1>::Zero());
  for (int k : dofs.order()) {
    const int j = dofs.joint_of(k);
    if (j >= 0) {
      const NodeJoint& joint = model.joints[j];
      const int p = joint.parent;
      const JointMaps maps = ComputeJointMaps(joint, state.x[p], state.R[p], state.x[k], state.z[k]);
      const Eigen::VectorXd zdot = W.segment(dofs.node_first(k), dofs.node_count(k));
      convective[k] = ChildConvective(joint, maps, state.x[p], state.R[p], state.x[k], NodeMotion(state, p, W), zdot,
                                      convective[p]);
    }
    acc[k] = NodeMotion(state, k, Wdot) + convective[k];
  }
  return acc;
}

NodeForces ZeroNodeForces(const SystemModel& model) {
  NodeForces f;
  f.f.assign(model.n_nodes(), Eigen::Matrix<double, 6, 1>::Zero());
  return f;
}

void AddJointGeometricStiffness(const SystemModel& model, const DofMap& dofs, const SystemState& state,
                                const NodeForces& forces, Triplets& tangent) {
  if (model.joints.empty()) return;
  // Transmitted forces, children before parents: t_p += A^T t_c.
  std::vector<Eigen::Matrix<double, 6, 1>> t = forces.f;
  const std::vector<int>& order = dofs.order();
  for (auto it = order.rbegin(); it != order.rend(); ++it) {
    const int c = *it, j = dofs.joint_of(c);
    if (j < 0) continue;
    const NodeJoint& joint = model.joints[j];
    const int p = joint.parent;
    const JointMaps maps = ComputeJointMaps(joint, state.x[p], state.R[p], state.x[c], state.z[c]);
    const JointGeometric g = ComputeJointGeometric(joint, maps, state.x[p], state.R[p], state.x[c], t[c]);
    const int first = dofs.node_first(c), d = joint.n_coordinates();
    // residual += J_p^T (A^T t_c) + E_c^T (B^T t_c); tangent = -d residual / dz, with
    // d pi_p / dz the rotation rows of J_p (sparse columns).
    for (const auto& [ci, vi] : state.J[p]) {
      for (const auto& [cj, vj] : state.J[p]) {
        const double v = vi.dot(g.dAf_dpi * vj.tail<3>());
        if (v != 0.0) tangent.emplace_back(ci, cj, -v);
      }
      for (int k = 0; k < d; ++k) {
        const double v = vi.dot(g.dAf_dz.col(k));
        if (v != 0.0) tangent.emplace_back(ci, first + k, -v);
      }
    }
    for (int k = 0; k < d; ++k) {
      for (const auto& [cj, vj] : state.J[p]) {
        const double v = g.dBf_dpi.row(k).dot(vj.tail<3>());
        if (v != 0.0) tangent.emplace_back(first + k, cj, -v);
      }
      for (int l = 0; l < d; ++l) {
        if (g.dBf_dz(k, l) != 0.0) tangent.emplace_back(first + k, first + l, -g.dBf_dz(k, l));
      }
    }
    t[p] += maps.A.transpose() * t[c];
  }
}

void Clamp(SystemModel& model, int k) { model.motion[k] = Eigen::MatrixXd(6, 0); }

void Pin(SystemModel& model, int k) {
  model.motion[k] = Eigen::MatrixXd::Zero(6, 3);
  model.motion[k].bottomRows(3).setIdentity();
}

void RevoluteToGround(SystemModel& model, int k, const Eigen::Vector3d& axis) {
  model.motion[k] = Eigen::MatrixXd::Zero(6, 1);
  model.motion[k].col(0).tail<3>() = axis.normalized();
}

void PrismaticToGround(SystemModel& model, int k, const Eigen::Vector3d& axis) {
  model.motion[k] = Eigen::MatrixXd::Zero(6, 1);
  model.motion[k].col(0).head<3>() = axis.normalized();
}

void CylindricalToGround(SystemModel& model, int k, const Eigen::Vector3d& axis) {
  model.motion[k] = Eigen::MatrixXd::Zero(6, 2);
  model.motion[k].col(0).head<3>() = axis.normalized();
  model.motion[k].col(1).tail<3>() = axis.normalized();
}

int AddNode(SystemModel& model, const std::string& name, const Eigen::Vector3d& x, const Eigen::Matrix3d& R) {
  model.node_names.push_back(name);
  model.node_x0.push_back(x);
  model.node_R0.push_back(R);
  model.motion.push_back(Eigen::MatrixXd::Identity(6, 6));
  return model.n_nodes() - 1;
}

SystemState InitialState(const SystemModel& model) {
  const DofMap dofs(model);
  SystemState s;
  s.x = model.node_x0;
  s.R = model.node_R0;
  for (int k = 0; k < model.n_nodes(); ++k) s.z.push_back(Eigen::VectorXd::Zero(dofs.node_count(k)));
  for (const SuperelementBody& body : model.bodies) {
    s.eta.push_back(Eigen::VectorXd::Zero(body.n_modes()));
    s.frames.push_back(body.InitialFrame());
  }
  s.lambda = Eigen::VectorXd::Zero(dofs.n_multipliers());
  UpdateKinematics(model, dofs, s);
  return s;
}

BodyConfiguration BodyConfigurationOf(const SystemModel& model, const SystemState& state, int b) {
  BodyConfiguration c;
  BodyConfigurationOf(model, state, b, c);
  return c;
}

void BodyConfigurationOf(const SystemModel& model, const SystemState& state, int b, BodyConfiguration& c) {
  const std::vector<int>& nodes = model.body_nodes[b];
  c.x.resize(nodes.size());
  c.R.resize(nodes.size());
  for (size_t a = 0; a < nodes.size(); ++a) {
    c.x[a] = state.x[nodes[a]];
    c.R[a] = state.R[nodes[a]];
  }
  c.eta = state.eta[b];
}

std::vector<MapEntry> BodyMap(const SystemModel& model, const DofMap& dofs, const SystemState& state, int b) {
  std::vector<MapEntry> map;
  BodyMap(model, dofs, state, b, map);
  return map;
}

void BodyMap(const SystemModel& model, const DofMap& dofs, const SystemState& state, int b, std::vector<MapEntry>& map) {
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
  const SuperelementBody& body = model.bodies[b];
  Eigen::VectorXd w = Eigen::VectorXd::Zero(body.n_coordinates());
  for (int a = 0; a < body.n_nodes(); ++a) w.segment<6>(6 * a) = NodeMotion(state, model.body_nodes[b][a], W);
  w.tail(body.n_modes()) = W.segment(dofs.mode_dof(b), body.n_modes());
  return w;
}

Eigen::VectorXd GatherBodyAcceleration(const SystemModel& model, const DofMap& dofs, int b,
                                       const std::vector<Eigen::Matrix<double, 6, 1>>& node_acc,
                                       const Eigen::VectorXd& Wdot) {
  const SuperelementBody& body = model.bodies[b];
  Eigen::VectorXd w = Eigen::VectorXd::Zero(body.n_coordinates());
  for (int a = 0; a < body.n_nodes(); ++a) w.segment<6>(6 * a) = node_acc[model.body_nodes[b][a]];
  w.tail(body.n_modes()) = Wdot.segment(dofs.mode_dof(b), body.n_modes());
  return w;
}

void AddBodyNodeForces(const SystemModel& model, int b, const Eigen::VectorXd& r_b, NodeForces& forces) {
  for (size_t a = 0; a < model.body_nodes[b].size(); ++a) {
    forces.Add(model.body_nodes[b][a], r_b.segment<6>(6 * a));
  }
}

SystemForces AssembleStatic(const SystemModel& model, const DofMap& dofs, SystemState& state, double lambda,
                            bool with_tangent) {
  SystemForces out;
  const int n = dofs.n_dofs();
  out.residual = Eigen::VectorXd::Zero(n);
  Triplets tangent;
  NodeForces node_forces = ZeroNodeForces(model);
  Eigen::VectorXd gravity = Eigen::VectorXd::Zero(n);
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    const SuperelementBody& body = model.bodies[b];
    const BodyConfiguration c = BodyConfigurationOf(model, state, int(b));
    const FrameSolution frame = body.SolveFrameFrom(c, state.frames[b]);
    if (!frame.ok) {
      out.ok = false;
      out.message = "floating frame of body " + std::to_string(b) + " did not converge";
      return out;
    }
    state.frames[b] = frame;
    const SuperelementBody::Data data = body.Evaluate(c, frame);
    Eigen::VectorXd f;
    Eigen::MatrixXd K;
    const bool gravity_on = model.static_gravity_end > 0 && model.gravity.squaredNorm() > 0;
    if (gravity_on && body.has_inertia_stiffening()) {
      // The stress of the body's own weight stiffens it (issue 13: load factors -R_j^T g at rest).
      const double ramp = std::min(lambda / model.static_gravity_end, 1.0);
      const Eigen::VectorXd zero = Eigen::VectorXd::Zero(body.n_coordinates());
      const InertiaLoadFactors load = body.InertiaLoads(data, zero, zero, ramp * model.gravity);
      body.ElasticForce(data, &f, with_tangent ? &K : nullptr, &load);
    } else {
      body.ElasticForce(data, &f, with_tangent ? &K : nullptr);
    }
    out.elastic_energy += body.ElasticEnergy(data);
    out.force_scale = std::max({out.force_scale, body.ForceNorm(f), body.force_floor()});
    out.roundoff += body.RoundOffForce(c);
    const Eigen::VectorXd minus_f = -f;
    ScatterBody(BodyMap(model, dofs, state, int(b)), &minus_f, with_tangent ? &K : nullptr, &out.residual,
                with_tangent ? &tangent : nullptr);
    AddBodyNodeForces(model, int(b), minus_f, node_forces);
    if (model.static_gravity_end > 0 && model.gravity.squaredNorm() > 0) {
      // Gravity in a static analysis, ramped to full at pseudo-time static_gravity_end (its
      // configuration derivative is left out of the tangent, as in the dynamic iteration matrix).
      const double ramp = std::min(lambda / model.static_gravity_end, 1.0);
      const Eigen::VectorXd f_grav = body.GravityForce(data, ramp * model.gravity);
      ScatterBody(BodyMap(model, dofs, state, int(b)), &f_grav, nullptr, &gravity, nullptr);
      AddBodyNodeForces(model, int(b), f_grav, node_forces);
    }
  }
  Eigen::VectorXd loads = Eigen::VectorXd::Zero(n);
  AddNodeLoads(model, state, lambda, loads, with_tangent ? &tangent : nullptr, &node_forces);
  loads += gravity;
  out.loads = loads;
  AddSpringDampers(model, state, Eigen::VectorXd(), loads, with_tangent ? &tangent : nullptr, nullptr,
                   &out.elastic_energy, &node_forces);
  out.residual += loads;
  out.force_scale = std::max(out.force_scale, (ResidualWeights(model, dofs).asDiagonal() * loads).norm());
  AddLoopConstraints(model, dofs, state, &out.residual, with_tangent ? &tangent : nullptr, &node_forces);
  out.node_forces = node_forces;
  if (with_tangent) {
    AddJointGeometricStiffness(model, dofs, state, node_forces, tangent);
    out.tangent = ToMatrix(n, tangent);
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
                      Eigen::VectorXd& residual, Triplets* K, Triplets* C, double* energy, NodeForces* node_forces) {
  for (const SpringDamper& s : model.springs) {
    Eigen::Vector3d x[2], v[2];
    const int nodes[2] = {s.node_a, s.node_b};
    std::vector<MapEntry> map;  // the 6 translational components (a, b) -> coordinates
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
    const Eigen::VectorXd fv = f.f;
    const Eigen::MatrixXd Km = f.K, Cm = f.C;
    ScatterBody(map, &fv, K ? &Km : nullptr, &residual, K);
    if (C) ScatterBody(map, nullptr, &Cm, nullptr, C);
  }
}

void ApplyIncrement(const SystemModel& model, const DofMap& dofs, const Eigen::VectorXd& delta, SystemState& state) {
  for (int k = 0; k < model.n_nodes(); ++k) {
    if (dofs.node_count(k) == 0) continue;
    const Eigen::VectorXd dz = delta.segment(dofs.node_first(k), dofs.node_count(k));
    state.z[k] += dz;
    const int j = dofs.joint_of(k);
    Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
    if (j < 0) {
      d = dofs.S(k) * dz;
      state.x[k] += d.head<3>();
    } else if (model.joints[j].type == JointType::kSpherical) {
      d.tail<3>() = dz;  // the child's own rotation; its position follows the parent
    }
    if (d.tail<3>().squaredNorm() > 0) state.R[k] = ExpSO3(Eigen::Vector3d(d.tail<3>())) * state.R[k];
  }
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    state.eta[b] += delta.segment(dofs.mode_dof(int(b)), model.bodies[b].n_modes());
  }
  if (dofs.n_multipliers() > 0) state.lambda += delta.tail(dofs.n_multipliers());
  UpdateKinematics(model, dofs, state);
}

void ApplyPrescribed(const SystemModel& model, const DofMap& dofs, double t, SystemState& state, Eigen::VectorXd* W,
                     Eigen::VectorXd* Wdot) {
  if (model.prescribed.empty()) return;
  Eigen::VectorXd delta = Eigen::VectorXd::Zero(dofs.n_dofs());
  for (const auto& p : model.prescribed) {
    const int j = dofs.prescribed_index(p);
    delta[j] = p.value(t) - state.z[p.node][p.coordinate];
    if (W) (*W)[j] = p.rate ? p.rate(t) : 0.0;
    if (Wdot) (*Wdot)[j] = p.acceleration ? p.acceleration(t) : 0.0;
  }
  ApplyIncrement(model, dofs, delta, state);
}

struct FreeSolver::Klu {
  klu_common common;
  klu_symbolic* symbolic = nullptr;
  klu_numeric* numeric = nullptr;
  // The free block of S in compressed columns; the pattern `symbolic` was analysed for.
  std::vector<int> outer, inner, analysed_outer, analysed_inner;
  std::vector<double> values;
  // The pivot ratio (min / max |u_ii|) of the last full factorization.
  double rcond = 0.0;
  Klu() {
    klu_defaults(&common);
    common.halt_if_singular = 1;
  }
  ~Klu() { Clear(); }
  void Clear() {
    if (numeric) klu_free_numeric(&numeric, &common);
    if (symbolic) klu_free_symbolic(&symbolic, &common);
  }
  // A full factorization (pivoting) with the kept analysis; false on a zero pivot.
  bool FactorAnew() {
    if (numeric) klu_free_numeric(&numeric, &common);
    numeric = klu_factor(outer.data(), inner.data(), values.data(), symbolic, &common);
    if (!numeric) return false;
    klu_rcond(symbolic, numeric, &common);
    rcond = common.rcond;
    return rcond > 0.0;
  }
};

FreeSolver::FreeSolver() : klu_(std::make_unique<Klu>()) {}
FreeSolver::~FreeSolver() = default;

bool FreeSolver::Factor(const DofMap& dofs, const SystemMatrix& S) {
  valid_ = false;
  Klu& k = *klu_;
  free_ = dofs.solved();
  const int n = int(free_.size());
  position_.assign(size_t(S.rows()), -1);
  for (int i = 0; i < n; ++i) position_[size_t(free_[size_t(i)])] = i;
  // The free block, column by column (free_ ascending keeps the rows sorted).
  k.outer.assign(size_t(n) + 1, 0);
  k.inner.clear();
  k.values.clear();
  for (int c = 0; c < n; ++c) {
    for (SystemMatrix::InnerIterator it(S, free_[size_t(c)]); it; ++it) {
      const int row = position_[size_t(it.row())];
      if (row < 0) continue;
      if (!std::isfinite(it.value())) return false;
      k.inner.push_back(row);
      k.values.push_back(it.value());
    }
    k.outer[size_t(c) + 1] = int(k.inner.size());
  }
  if (n == 0) return valid_ = true;
  // Loop constraints: the multipliers' rows (G, of order 1) and columns (G^T) meet coordinates
  // whose diagonal may be of order m / (beta h^2) (Arnold & Bruls 2007: the index-3 iteration
  // matrix's condition grows as h^-2 unscaled). Row and column of multiplier i are scaled by
  // s_i, the largest |S_jj| of the coordinates its equation involves: the factor is of D S D,
  // D = diag(1, ..., s_i), and Solve returns D (D S D)^-1 D r.
  scale_ = Eigen::VectorXd::Ones(n);
  if (dofs.n_multipliers() > 0) {
    Eigen::VectorXd diagonal = Eigen::VectorXd::Zero(n), s = Eigen::VectorXd::Zero(n);
    for (int c = 0; c < n; ++c)
      for (int p = k.outer[size_t(c)]; p < k.outer[size_t(c) + 1]; ++p)
        if (k.inner[size_t(p)] == c) diagonal[c] = std::abs(k.values[size_t(p)]);
    for (int c = 0; c < n; ++c) {
      if (dofs.multiplier(free_[size_t(c)])) continue;
      for (int p = k.outer[size_t(c)]; p < k.outer[size_t(c) + 1]; ++p) {
        const int row = k.inner[size_t(p)];
        if (dofs.multiplier(free_[size_t(row)])) s[row] = std::max(s[row], diagonal[c]);
      }
    }
    for (int i = 0; i < n; ++i)
      if (dofs.multiplier(free_[size_t(i)]) && s[i] > 0) scale_[i] = s[i];
    for (int c = 0; c < n; ++c)
      for (int p = k.outer[size_t(c)]; p < k.outer[size_t(c) + 1]; ++p)
        k.values[size_t(p)] *= scale_[k.inner[size_t(p)]] * scale_[c];
  }
  // The diagonal scaling d_i = 1 / sqrt|s_ii| of the singularity test below.
  Eigen::VectorXd d = Eigen::VectorXd::Ones(n);
  for (int c = 0; c < n; ++c)
    for (int p = k.outer[size_t(c)]; p < k.outer[size_t(c) + 1]; ++p)
      if (k.inner[size_t(p)] == c && k.values[size_t(p)] != 0.0) d[c] = 1.0 / std::sqrt(std::abs(k.values[size_t(p)]));
  bool factored = false;
  if (!k.symbolic || k.outer != k.analysed_outer || k.inner != k.analysed_inner) {
    // A new pattern (the first factorization, or the model's structure changed).
    k.Clear();
    k.symbolic = klu_analyze(n, k.outer.data(), k.inner.data(), &k.common);
    if (!k.symbolic) return false;
    ++analysed_;
    k.analysed_outer = k.outer;
    k.analysed_inner = k.inner;
  } else if (k.numeric && klu_refactor(k.outer.data(), k.inner.data(), k.values.data(), k.symbolic, k.numeric, &k.common)) {
    // The kept pivot order, while its pivots stay as good as the last full factorization's (the
    // ratio of the smallest to the largest, O(n); the pivot growth would cost a factorization).
    klu_rcond(k.symbolic, k.numeric, &k.common);
    factored = k.common.rcond > 1e-3 * k.rcond;
    if (factored) ++refactored_;
  }
  if (!factored) {
    if (!k.FactorAnew()) return false;
    ++full_;
  }
  // Singular or not is a property of the matrix scaled to unit diagonal, D S D (translations,
  // rotations and modal coordinates in any units alike): its inverse D^-1 S^-1 D^-1 is probed
  // with the factor on two fixed +-1 vectors (an O(nnz) estimate of ||(D S D)^-1||_1); singular
  // when ||D S D||_1 ||(D S D)^-1||_1 > 1e15. The solve itself stays unscaled.
  double norm = 0.0;
  for (int c = 0; c < n; ++c) {
    double column = 0.0;
    for (int p = k.outer[size_t(c)]; p < k.outer[size_t(c) + 1]; ++p)
      column += std::abs(d[k.inner[size_t(p)]] * k.values[size_t(p)] * d[c]);
    norm = std::max(norm, column);
  }
  double inverse = 0.0;
  for (int probe = 0; probe < 2; ++probe) {
    Eigen::VectorXd x(n), y(n);
    for (int i = 0; i < n; ++i) x[i] = ((i * (probe + 3) + probe) % 5 < 2) ? -1.0 : 1.0;
    y = d.cwiseInverse().asDiagonal() * x;
    klu_solve(k.symbolic, k.numeric, n, 1, y.data(), &k.common);
    y = d.cwiseInverse().asDiagonal() * y;
    if (!y.allFinite()) return false;
    inverse = std::max(inverse, y.lpNorm<1>() / x.lpNorm<1>());
  }
  valid_ = norm * inverse < 1e15;
  return valid_;
}

Eigen::VectorXd FreeSolver::Solve(const Eigen::VectorXd& r) const {
  Eigen::VectorXd rf(free_.size());
  for (size_t i = 0; i < free_.size(); ++i) rf[i] = r[free_[i]] * scale_[Eigen::Index(i)];
  if (rf.size() > 0) klu_solve(klu_->symbolic, klu_->numeric, int(rf.size()), 1, rf.data(), &klu_->common);
  Eigen::VectorXd d = Eigen::VectorXd::Zero(r.size());
  for (size_t i = 0; i < free_.size(); ++i) d[free_[i]] = rf[i] * scale_[Eigen::Index(i)];
  return d;
}

Eigen::VectorXd SolveFree(const DofMap& dofs, const SystemMatrix& S, const Eigen::VectorXd& r) {
  FreeSolver solver;
  if (!solver.Factor(dofs, S)) return Eigen::VectorXd::Constant(r.size(), std::nan(""));
  return solver.Solve(r);
}

std::vector<Eigen::Matrix<double, 6, 1>> JointReactions(const SystemModel& model, const DofMap& dofs,
                                                        const SystemState& state, const NodeForces& forces) {
  std::vector<Eigen::Matrix<double, 6, 1>> t = forces.f;  // transmitted, children first
  const std::vector<int>& order = dofs.order();
  for (auto it = order.rbegin(); it != order.rend(); ++it) {
    const int c = *it, j = dofs.joint_of(c);
    if (j < 0) continue;
    const NodeJoint& joint = model.joints[j];
    const JointMaps maps = ComputeJointMaps(joint, state.x[joint.parent], state.R[joint.parent], state.x[c], state.z[c]);
    t[joint.parent] += maps.A.transpose() * t[c];
  }
  std::vector<Eigen::Matrix<double, 6, 1>> reactions(model.n_nodes(), Eigen::Matrix<double, 6, 1>::Zero());
  for (int k = 0; k < model.n_nodes(); ++k) {
    const bool held = dofs.joint_of(k) >= 0 || dofs.S(k).cols() < 6;
    if (held) reactions[k] = -t[k];
  }
  // A node that is the child of cut joints and held otherwise by nothing or by a rigid joint (a
  // rigid body's point hangs on its body by one): the cut joints' reactions. That is what the
  // scene's joint at the node exerts; the rigid offset's force is internal to the body.
  const std::vector<Eigen::Matrix<double, 6, 1>> cut = CutJointReactions(model, state);
  std::vector<bool> replaced(model.n_nodes(), false);
  for (size_t c = 0; c < cut.size(); ++c) {
    const int k = model.cut_joints[c].joint.child, j = dofs.joint_of(k);
    const bool tree_held = j >= 0 ? model.joints[j].type != JointType::kRigid : dofs.S(k).cols() < 6;
    if (tree_held) continue;
    if (!replaced[k]) reactions[k].setZero();
    replaced[k] = true;
    reactions[k] += cut[c];
  }
  return reactions;
}

Eigen::MatrixXd DenseFreeMatrix(const DofMap& dofs, const SystemMatrix& S) {
  const std::vector<int>& free = dofs.solved();
  const int n = int(free.size());
  std::vector<int> position(S.rows(), -1);
  for (int i = 0; i < n; ++i) position[free[i]] = i;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  for (int col = 0; col < S.outerSize(); ++col)
    for (SystemMatrix::InnerIterator it(S, col); it; ++it)
      if (position[it.row()] >= 0 && position[col] >= 0) A(position[it.row()], position[col]) += it.value();
  return A;
}

std::string RoundOffToleranceWarning(double tolerance) {
  if (tolerance >= kRoundOffTolerance) return "";
  char buffer[200];
  std::snprintf(buffer, sizeof buffer, "analysis.tolerance %.3g is below the round-off floor of the residual; using %.0e",
                tolerance, kRoundOffTolerance);
  return buffer;
}

double BoundingDiagonal(const std::vector<Eigen::Vector3d>& points) {
  if (points.size() < 2) return 0.0;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(HUGE_VAL), hi = -lo;
  for (const Eigen::Vector3d& x : points) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
  return (hi - lo).norm();
}

Eigen::VectorXd ResidualWeights(const SystemModel& model, const DofMap& dofs) {
  double L = BoundingDiagonal(model.node_x0);
  if (!(L > 0)) L = 1.0;
  Eigen::VectorXd w = Eigen::VectorXd::Ones(dofs.n_dofs());
  for (int k = 0; k < model.n_nodes(); ++k) {
    const int first = dofs.node_first(k), j = dofs.joint_of(k);
    if (j < 0) {
      const Eigen::MatrixXd& S = dofs.S(k);
      for (int c = 0; c < S.cols(); ++c) {
        if (S.col(c).tail<3>().norm() > 0) w[first + c] = 1.0 / L;
      }
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
  return w;
}

double FreeNorm(const DofMap& dofs, const Eigen::VectorXd& r, const Eigen::VectorXd& weights) {
  double s = 0;
  for (int j : dofs.solved()) s += weights[j] * weights[j] * r[j] * r[j];
  return std::sqrt(s);
}

}  // namespace femb
