#include "solver/assembly/system.h"

#include <Eigen/Dense>

#include "solver/rotation.h"

namespace femb {

DofMap::DofMap(const SystemModel& model) : motion_(&model.motion) {
  for (int k = 0; k < model.n_nodes(); ++k) {
    node_first_.push_back(n_dofs_);
    n_dofs_ += int(model.motion[k].cols());
  }
  for (const SuperelementBody& body : model.bodies) {
    mode_dof_.push_back(n_dofs_);
    n_dofs_ += body.n_modes();
  }
  prescribed_.assign(n_dofs_, false);
  for (const auto& p : model.prescribed) prescribed_[prescribed_index(p)] = true;
  for (int j = 0; j < n_dofs_; ++j) {
    if (!prescribed_[j]) solved_.push_back(j);
  }
}

Eigen::Matrix<double, 6, 1> DofMap::NodeMotion(int k, const Eigen::VectorXd& z) const {
  if (node_count(k) == 0 || z.size() == 0) return Eigen::Matrix<double, 6, 1>::Zero();
  return S(k) * z.segment(node_first_[k], node_count(k));
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
  SystemState s;
  s.x = model.node_x0;
  s.R = model.node_R0;
  for (int k = 0; k < model.n_nodes(); ++k) s.z.push_back(Eigen::VectorXd::Zero(model.motion[k].cols()));
  for (const SuperelementBody& body : model.bodies) {
    s.eta.push_back(Eigen::VectorXd::Zero(body.n_modes()));
    s.frames.push_back(body.InitialFrame());
  }
  return s;
}

BodyConfiguration BodyConfigurationOf(const SystemModel& model, const SystemState& state, int b) {
  BodyConfiguration c;
  for (int node : model.body_nodes[b]) {
    c.x.push_back(state.x[node]);
    c.R.push_back(state.R[node]);
  }
  c.eta = state.eta[b];
  return c;
}

std::vector<MapEntry> BodyMap(const SystemModel& model, const DofMap& dofs, int b) {
  const SuperelementBody& body = model.bodies[b];
  std::vector<MapEntry> map;
  for (int a = 0; a < body.n_nodes(); ++a) {
    const int k = model.body_nodes[b][a];
    const Eigen::MatrixXd& S = dofs.S(k);
    for (int i = 0; i < 6; ++i) {
      for (int j = 0; j < S.cols(); ++j) {
        if (S(i, j) != 0.0) map.push_back({6 * a + i, dofs.node_first(k) + j, S(i, j)});
      }
    }
  }
  for (int m = 0; m < body.n_modes(); ++m) map.push_back({6 * body.n_nodes() + m, dofs.mode_dof(b) + m, 1.0});
  return map;
}

void ScatterBody(const std::vector<MapEntry>& map, const Eigen::VectorXd* f, const Eigen::MatrixXd* K,
                 Eigen::VectorXd* F, Eigen::MatrixXd* KK) {
  for (const MapEntry& a : map) {
    if (f && F) (*F)[a.coordinate] += a.coefficient * (*f)[a.local];
    if (!K || !KK) continue;
    for (const MapEntry& b : map) {
      (*KK)(a.coordinate, b.coordinate) += a.coefficient * b.coefficient * (*K)(a.local, b.local);
    }
  }
}

Eigen::VectorXd GatherBody(const SystemModel& model, const DofMap& dofs, int b, const Eigen::VectorXd& W) {
  Eigen::VectorXd w = Eigen::VectorXd::Zero(model.bodies[b].n_coordinates());
  for (const MapEntry& e : BodyMap(model, dofs, b)) w[e.local] += e.coefficient * W[e.coordinate];
  return w;
}

SystemForces AssembleStatic(const SystemModel& model, const DofMap& dofs, SystemState& state, double lambda,
                            bool with_tangent) {
  SystemForces out;
  const int n = dofs.n_dofs();
  out.residual = Eigen::VectorXd::Zero(n);
  if (with_tangent) out.tangent = Eigen::MatrixXd::Zero(n, n);
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    const SuperelementBody& body = model.bodies[b];
    const BodyConfiguration c = BodyConfigurationOf(model, state, int(b));
    FrameSolution frame = body.SolveFrame(c, state.frames[b]);
    if (!frame.ok) frame = body.SolveFrame(c, body.GuessFrame(c));
    if (!frame.ok) {
      out.ok = false;
      out.message = "floating frame of body " + std::to_string(b) + " did not converge";
      return out;
    }
    state.frames[b] = frame;
    Eigen::VectorXd f;
    Eigen::MatrixXd K;
    body.ElasticForce(c, frame, &f, with_tangent ? &K : nullptr);
    out.elastic_energy += body.ElasticEnergy(c, frame);
    out.force_scale = std::max({out.force_scale, f.norm(), body.force_floor()});
    const Eigen::VectorXd minus_f = -f;
    ScatterBody(BodyMap(model, dofs, int(b)), &minus_f, with_tangent ? &K : nullptr, &out.residual,
                with_tangent ? &out.tangent : nullptr);
  }
  Eigen::VectorXd loads = Eigen::VectorXd::Zero(n);
  AddNodeLoads(model, dofs, state, lambda, loads, with_tangent ? &out.tangent : nullptr);
  AddSpringDampers(model, dofs, state, Eigen::VectorXd(), loads, with_tangent ? &out.tangent : nullptr, nullptr,
                   &out.elastic_energy);
  out.residual += loads;
  out.force_scale = std::max(out.force_scale, loads.norm());
  return out;
}

void AddNodeLoads(const SystemModel& model, const DofMap& dofs, const SystemState& state, double t,
                  Eigen::VectorXd& residual, Eigen::MatrixXd* tangent) {
  for (const NodeLoad& load : model.loads) {
    const Eigen::MatrixXd& S = dofs.S(load.node);
    if (S.cols() == 0) continue;  // clamped: the support takes it
    const int first = dofs.node_first(load.node);
    const double s = load.Scale(t);
    const Eigen::Matrix3d& R = state.R[load.node];
    const Eigen::Vector3d F = s * (load.follower ? Eigen::Vector3d(R * load.force) : load.force);
    const Eigen::Vector3d Mo = s * (load.follower ? Eigen::Vector3d(R * load.moment) : load.moment);
    Eigen::Matrix<double, 6, 1> f;
    f << F, Mo;
    residual.segment(first, S.cols()) += S.transpose() * f;
    if (tangent && load.follower) {
      // d(R F_loc)/d pi = -(R F_loc)~: enters the tangent of f_int - f_ext with a plus sign.
      Eigen::Matrix<double, 6, 6> K = Eigen::Matrix<double, 6, 6>::Zero();
      K.block<3, 3>(0, 3) = Skew<double>(F);
      K.block<3, 3>(3, 3) = Skew<double>(Mo);
      tangent->block(first, first, S.cols(), S.cols()) += S.transpose() * K * S;
    }
  }
}

void AddSpringDampers(const SystemModel& model, const DofMap& dofs, const SystemState& state, const Eigen::VectorXd& W,
                      Eigen::VectorXd& residual, Eigen::MatrixXd* K, Eigen::MatrixXd* C, double* energy) {
  for (const SpringDamper& s : model.springs) {
    Eigen::Vector3d x[2], v[2];
    const int nodes[2] = {s.node_a, s.node_b};
    std::vector<MapEntry> map;  // the 6 translational components (a, b) -> coordinates
    for (int e = 0; e < 2; ++e) {
      const int k = nodes[e];
      x[e] = k >= 0 ? state.x[k] : s.ground;
      v[e] = k >= 0 ? Eigen::Vector3d(dofs.NodeMotion(k, W).head<3>()) : Eigen::Vector3d::Zero();
      if (k < 0) continue;
      const Eigen::MatrixXd& S = dofs.S(k);
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < S.cols(); ++j) {
          if (S(i, j) != 0.0) map.push_back({3 * e + i, dofs.node_first(k) + j, S(i, j)});
        }
      }
    }
    const SpringDamperForces f = EvaluateSpringDamper(s, x[0], x[1], v[0], v[1]);
    if (energy) *energy += f.energy;
    const Eigen::VectorXd fv = f.f;
    const Eigen::MatrixXd Km = f.K, Cm = f.C;
    ScatterBody(map, &fv, K ? &Km : nullptr, &residual, K);
    if (C) ScatterBody(map, nullptr, &Cm, nullptr, C);
  }
}

void ApplyIncrement(const SystemModel& model, const DofMap& dofs, const Eigen::VectorXd& delta, SystemState& state) {
  for (int k = 0; k < model.n_nodes(); ++k) {
    if (dofs.node_count(k) == 0) continue;
    const Eigen::Matrix<double, 6, 1> d = dofs.NodeMotion(k, delta);
    state.z[k] += delta.segment(dofs.node_first(k), dofs.node_count(k));
    state.x[k] += d.head<3>();
    if (d.tail<3>().squaredNorm() > 0) state.R[k] = ExpSO3(Eigen::Vector3d(d.tail<3>())) * state.R[k];
  }
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    state.eta[b] += delta.segment(dofs.mode_dof(int(b)), model.bodies[b].n_modes());
  }
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

Eigen::VectorXd SolveFree(const DofMap& dofs, const Eigen::MatrixXd& S, const Eigen::VectorXd& r) {
  const std::vector<int>& f = dofs.solved();
  Eigen::VectorXd d = Eigen::VectorXd::Zero(r.size());
  if (f.size() == size_t(r.size())) return S.partialPivLu().solve(r);
  Eigen::MatrixXd Sf(f.size(), f.size());
  Eigen::VectorXd rf(f.size());
  for (size_t i = 0; i < f.size(); ++i) {
    rf[i] = r[f[i]];
    for (size_t j = 0; j < f.size(); ++j) Sf(i, j) = S(f[i], f[j]);
  }
  const Eigen::VectorXd df = Sf.partialPivLu().solve(rf);
  for (size_t i = 0; i < f.size(); ++i) d[f[i]] = df[i];
  return d;
}

double FreeNorm(const DofMap& dofs, const Eigen::VectorXd& r) {
  double s = 0;
  for (int j : dofs.solved()) s += r[j] * r[j];
  return std::sqrt(s);
}

}  // namespace femb
