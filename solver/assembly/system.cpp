#include "solver/assembly/system.h"

#include "solver/rotation.h"

namespace femb {

DofMap::DofMap(const SystemModel& model) {
  for (int k = 0; k < model.n_nodes(); ++k) {
    node_dof_.push_back(model.grounded[k] ? -1 : n_dofs_);
    if (!model.grounded[k]) n_dofs_ += 6;
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
  model.grounded.push_back(false);
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
    // Scatter: local coordinate index -> system unknown (-1 grounded).
    std::vector<int> map(body.n_coordinates(), -1);
    for (int a = 0; a < body.n_nodes(); ++a) {
      const int first = dofs.node_dof(model.body_nodes[b][a]);
      for (int i = 0; i < 6 && first >= 0; ++i) map[6 * a + i] = first + i;
    }
    for (int m = 0; m < body.n_modes(); ++m) map[6 * body.n_nodes() + m] = dofs.mode_dof(int(b)) + m;
    for (int i = 0; i < body.n_coordinates(); ++i) {
      if (map[i] < 0) continue;
      out.residual[map[i]] -= f[i];
      if (!with_tangent) continue;
      for (int j = 0; j < body.n_coordinates(); ++j) {
        if (map[j] >= 0) out.tangent(map[i], map[j]) += K(i, j);
      }
    }
  }
  for (const NodeLoad& load : model.loads) {
    const int first = dofs.node_dof(load.node);
    if (first < 0) continue;
    const Eigen::Matrix3d& R = state.R[load.node];
    const Eigen::Vector3d F = lambda * (load.follower ? Eigen::Vector3d(R * load.force) : load.force);
    const Eigen::Vector3d Mo = lambda * (load.follower ? Eigen::Vector3d(R * load.moment) : load.moment);
    out.residual.segment<3>(first) += F;
    out.residual.segment<3>(first + 3) += Mo;
    if (with_tangent && load.follower) {
      // d(R F_loc)/d pi = -(R F_loc)~: enters the tangent of f_int - f_ext with a plus sign.
      out.tangent.block<3, 3>(first, first + 3) += Skew<double>(F);
      out.tangent.block<3, 3>(first + 3, first + 3) += Skew<double>(Mo);
    }
  }
  return out;
}

void ApplyIncrement(const SystemModel& model, const DofMap& dofs, const Eigen::VectorXd& delta, SystemState& state) {
  for (int k = 0; k < model.n_nodes(); ++k) {
    const int first = dofs.node_dof(k);
    if (first < 0) continue;
    state.x[k] += delta.segment<3>(first);
    state.R[k] = ExpSO3(Eigen::Vector3d(delta.segment<3>(first + 3))) * state.R[k];
  }
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    state.eta[b] += delta.segment(dofs.mode_dof(int(b)), model.bodies[b].n_modes());
  }
}

}  // namespace femb
