#include "solver/assembly/system.h"

#include "solver/rotation.h"

namespace femb {

DofMap::DofMap(const SystemModel& model) {
  for (int k = 0; k < model.n_nodes(); ++k) {
    for (int i = 0; i < 6; ++i) node_dof_.push_back(model.fixed[k][i] ? -1 : n_dofs_++);
  }
  for (const SuperelementBody& body : model.bodies) {
    mode_dof_.push_back(n_dofs_);
    n_dofs_ += body.n_modes();
  }
}

int AddNode(SystemModel& model, const std::string& name, const Eigen::Vector3d& x, const Eigen::Matrix3d& R) {
  model.node_names.push_back(name);
  model.node_x0.push_back(x);
  model.node_R0.push_back(R);
  model.fixed.push_back({false, false, false, false, false, false});
  return model.n_nodes() - 1;
}

SystemState InitialState(const SystemModel& model) {
  SystemState s;
  s.x = model.node_x0;
  s.R = model.node_R0;
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
    out.force_scale = std::max(out.force_scale, f.norm());
    const std::vector<int> map = BodyDofMap(model, dofs, int(b));
    for (int i = 0; i < body.n_coordinates(); ++i) {
      if (map[i] < 0) continue;
      out.residual[map[i]] -= f[i];
      if (!with_tangent) continue;
      for (int j = 0; j < body.n_coordinates(); ++j) {
        if (map[j] >= 0) out.tangent(map[i], map[j]) += K(i, j);
      }
    }
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
    const double s = load.Scale(t);
    const Eigen::Matrix3d& R = state.R[load.node];
    const Eigen::Vector3d F = s * (load.follower ? Eigen::Vector3d(R * load.force) : load.force);
    const Eigen::Vector3d Mo = s * (load.follower ? Eigen::Vector3d(R * load.moment) : load.moment);
    Eigen::Matrix<double, 6, 1> f;
    f << F, Mo;
    Eigen::Matrix<double, 6, 3> stiffness = Eigen::Matrix<double, 6, 3>::Zero();  // d(-f_ext)/d pi
    if (load.follower) stiffness << Skew<double>(F), Skew<double>(Mo);
    for (int i = 0; i < 6; ++i) {
      const int row = dofs.node_dof(load.node, i);
      if (row < 0) continue;  // reaction: taken by the support
      residual[row] += f[i];
      if (!tangent || !load.follower) continue;
      for (int j = 0; j < 3; ++j) {
        const int col = dofs.node_dof(load.node, 3 + j);
        if (col >= 0) (*tangent)(row, col) += stiffness(i, j);
      }
    }
  }
}

void AddSpringDampers(const SystemModel& model, const DofMap& dofs, const SystemState& state, const Eigen::VectorXd& W,
                      Eigen::VectorXd& residual, Eigen::MatrixXd* K, Eigen::MatrixXd* C, double* energy) {
  for (const SpringDamper& s : model.springs) {
    int rows[6];
    Eigen::Vector3d x[2], v[2];
    const int nodes[2] = {s.node_a, s.node_b};
    for (int e = 0; e < 2; ++e) {
      const int k = nodes[e];
      x[e] = k >= 0 ? state.x[k] : s.ground;
      v[e].setZero();
      for (int i = 0; i < 3; ++i) {
        rows[3 * e + i] = k >= 0 ? dofs.node_dof(k, i) : -1;
        if (rows[3 * e + i] >= 0 && W.size()) v[e][i] = W[rows[3 * e + i]];
      }
    }
    const SpringDamperForces f = EvaluateSpringDamper(s, x[0], x[1], v[0], v[1]);
    if (energy) *energy += f.energy;
    for (int i = 0; i < 6; ++i) {
      if (rows[i] < 0) continue;
      residual[rows[i]] += f.f[i];
      for (int j = 0; j < 6; ++j) {
        if (rows[j] < 0) continue;
        if (K) (*K)(rows[i], rows[j]) += f.K(i, j);
        if (C) (*C)(rows[i], rows[j]) += f.C(i, j);
      }
    }
  }
}

std::vector<int> BodyDofMap(const SystemModel& model, const DofMap& dofs, int b) {
  const SuperelementBody& body = model.bodies[b];
  std::vector<int> map(body.n_coordinates(), -1);
  for (int a = 0; a < body.n_nodes(); ++a) {
    for (int i = 0; i < 6; ++i) map[6 * a + i] = dofs.node_dof(model.body_nodes[b][a], i);
  }
  for (int m = 0; m < body.n_modes(); ++m) map[6 * body.n_nodes() + m] = dofs.mode_dof(b) + m;
  return map;
}

Eigen::VectorXd GatherBody(const SystemModel& model, const DofMap& dofs, int b, const Eigen::VectorXd& W) {
  const std::vector<int> map = BodyDofMap(model, dofs, b);
  Eigen::VectorXd w = Eigen::VectorXd::Zero(map.size());
  for (size_t i = 0; i < map.size(); ++i) {
    if (map[i] >= 0) w[i] = W[map[i]];
  }
  return w;
}

void ApplyIncrement(const SystemModel& model, const DofMap& dofs, const Eigen::VectorXd& delta, SystemState& state) {
  for (int k = 0; k < model.n_nodes(); ++k) {
    Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
    for (int i = 0; i < 6; ++i) {
      if (dofs.node_dof(k, i) >= 0) d[i] = delta[dofs.node_dof(k, i)];
    }
    state.x[k] += d.head<3>();
    if (d.tail<3>().squaredNorm() > 0) state.R[k] = ExpSO3(Eigen::Vector3d(d.tail<3>())) * state.R[k];
  }
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    state.eta[b] += delta.segment(dofs.mode_dof(int(b)), model.bodies[b].n_modes());
  }
}

}  // namespace femb
