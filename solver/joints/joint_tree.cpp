#include "solver/joints/joint_tree.h"

#include <Eigen/Dense>
#include <vector>

#include "solver/joints/loop_constraints.h"
#include "solver/rotation.h"

namespace femb {

ParentNode ParentOf(const SystemState& state, int p) {
  static const Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  static const Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
  static const NodeJacobian none;
  if (p == kGround) return {origin, axes, none};
  return {state.x[size_t(p)], state.R[size_t(p)], state.J[size_t(p)]};
}

Eigen::Matrix<double, 6, 1> NodeMotion(const SystemState& state, int k, const Eigen::VectorXd& dz) {
  Eigen::Matrix<double, 6, 1> v = Eigen::Matrix<double, 6, 1>::Zero();
  if (dz.size() == 0 || k == kGround) return v;
  for (const auto& [col, vec] : state.J[k]) v += vec * dz[col];
  return v;
}

void UpdateKinematics(const SystemModel& model, const DofMap& dofs, SystemState& state) {
  state.J.resize(size_t(model.n_nodes()));
  for (NodeJacobian& J : state.J) J.clear();  // their storage is kept: no allocation once sized
  for (int k : dofs.order()) {
    const int j = dofs.joint_of(k);
    NodeJacobian& J = state.J[k];
    if (j < 0) {  // free: its own spatial increments
      for (int c = 0; c < 6; ++c) J.emplace_back(dofs.node_first(k) + c, Eigen::Matrix<double, 6, 1>::Unit(c));
      continue;
    }
    const NodeJoint& joint = model.joints[j];
    const ParentNode parent = ParentOf(state, joint.parent);
    PlaceChild(joint, parent.x, parent.R, state.z[k], &state.x[k], &state.R[k]);
    const JointMaps maps = ComputeJointMaps(joint, parent.x, parent.R, state.x[k], state.z[k]);
    for (const auto& [col, vec] : parent.J) {
      const Eigen::Matrix<double, 6, 1> v = maps.A * vec;
      if (v.squaredNorm() > 0) J.emplace_back(col, v);
    }
    for (int c = 0; c < joint.n_coordinates(); ++c) J.emplace_back(dofs.node_first(k) + c, maps.B.col(c));
  }
}

std::vector<Eigen::Matrix<double, 6, 1>> NodeAccelerations(const SystemModel& model, const DofMap& dofs,
                                                           const SystemState& state, const Eigen::VectorXd& W,
                                                           const Eigen::VectorXd& Wdot) {
  std::vector<Eigen::Matrix<double, 6, 1>> acc;
  NodeAccelerations(model, dofs, state, W, Wdot, acc);
  return acc;
}

void NodeAccelerations(const SystemModel& model, const DofMap& dofs, const SystemState& state, const Eigen::VectorXd& W,
                       const Eigen::VectorXd& Wdot, std::vector<Eigen::Matrix<double, 6, 1>>& acc,
                       SystemScratch* scratch) {
  SystemScratch own;
  std::vector<Eigen::Matrix<double, 6, 1>>& convective = (scratch ? *scratch : own).convective;
  acc.assign(size_t(model.n_nodes()), Eigen::Matrix<double, 6, 1>::Zero());
  convective.assign(size_t(model.n_nodes()), Eigen::Matrix<double, 6, 1>::Zero());
  for (int k : dofs.order()) {
    const int j = dofs.joint_of(k);
    if (j >= 0) {
      const NodeJoint& joint = model.joints[j];
      const int p = joint.parent;
      const ParentNode parent = ParentOf(state, p);
      const JointMaps maps = ComputeJointMaps(joint, parent.x, parent.R, state.x[k], state.z[k]);
      convective[k] = ChildConvective(joint, maps, parent.x, parent.R, state.x[k], NodeMotion(state, p, W),
                                      W.segment(dofs.node_first(k), dofs.node_count(k)),
                                      p == kGround ? Eigen::Matrix<double, 6, 1>::Zero() : convective[p]);
    }
    acc[k] = NodeMotion(state, k, Wdot) + convective[k];
  }
}

NodeForces ZeroNodeForces(const SystemModel& model) {
  NodeForces f;
  f.f.assign(model.n_nodes(), Eigen::Matrix<double, 6, 1>::Zero());
  return f;
}

void AddJointGeometricStiffness(const SystemModel& model, const DofMap& dofs, const SystemState& state,
                                const NodeForces& forces, Triplets& tangent, SystemScratch* scratch) {
  if (model.joints.empty()) return;
  // Transmitted forces, children before parents: t_p += A^T t_c.
  SystemScratch own;
  std::vector<Eigen::Matrix<double, 6, 1>>& t = (scratch ? *scratch : own).transmitted;
  t = forces.f;
  const std::vector<int>& order = dofs.order();
  for (auto it = order.rbegin(); it != order.rend(); ++it) {
    const int c = *it, j = dofs.joint_of(c);
    if (j < 0 || ConstantMaps(model.joints[j])) continue;  // a support passes nothing on either
    const NodeJoint& joint = model.joints[j];
    const int p = joint.parent;
    const ParentNode parent = ParentOf(state, p);
    const JointMaps maps = ComputeJointMaps(joint, parent.x, parent.R, state.x[c], state.z[c]);
    const JointGeometric g = ComputeJointGeometric(joint, maps, parent.x, parent.R, state.x[c], t[c]);
    const int first = dofs.node_first(c), d = joint.n_coordinates();
    // residual += J_p^T (A^T t_c) + E_c^T (B^T t_c); tangent = -d residual / dz, with
    // d pi_p / dz the rotation rows of J_p (sparse columns).
    for (const auto& [ci, vi] : parent.J) {
      for (const auto& [cj, vj] : parent.J) {
        const double v = vi.dot(g.dAf_dpi * vj.tail<3>());
        if (v != 0.0) tangent.emplace_back(ci, cj, -v);
      }
      for (int k = 0; k < d; ++k) {
        const double v = vi.dot(g.dAf_dz.col(k));
        if (v != 0.0) tangent.emplace_back(ci, first + k, -v);
      }
    }
    for (int k = 0; k < d; ++k) {
      for (const auto& [cj, vj] : parent.J) {
        const double v = g.dBf_dpi.row(k).dot(vj.tail<3>());
        if (v != 0.0) tangent.emplace_back(first + k, cj, -v);
      }
      for (int l = 0; l < d; ++l) {
        if (g.dBf_dz(k, l) != 0.0) tangent.emplace_back(first + k, first + l, -g.dBf_dz(k, l));
      }
    }
    if (p != kGround) t[p] += maps.A.transpose() * t[c];
  }
}

std::vector<Eigen::Matrix<double, 6, 1>> JointReactions(const SystemModel& model, const DofMap& dofs,
                                                        const SystemState& state, const NodeForces& forces) {
  std::vector<Eigen::Matrix<double, 6, 1>> t = forces.f;  // transmitted, children first
  const std::vector<int>& order = dofs.order();
  for (auto it = order.rbegin(); it != order.rend(); ++it) {
    const int c = *it, j = dofs.joint_of(c);
    if (j < 0) continue;
    const NodeJoint& joint = model.joints[j];
    if (joint.parent == kGround) continue;  // what the ground takes
    const ParentNode parent = ParentOf(state, joint.parent);
    const JointMaps maps = ComputeJointMaps(joint, parent.x, parent.R, state.x[c], state.z[c]);
    t[joint.parent] += maps.A.transpose() * t[c];
  }
  std::vector<Eigen::Matrix<double, 6, 1>> reactions(model.n_nodes(), Eigen::Matrix<double, 6, 1>::Zero());
  for (int k = 0; k < model.n_nodes(); ++k) {
    if (!dofs.free(k)) reactions[k] = -t[k];  // held by a joint to a parent or to the ground
  }
  // A node that is the child of cut joints and held otherwise by nothing or by a rigid joint (a
  // rigid body's point hangs on its body by one): the cut joints' reactions. That is what the
  // scene's joint at the node exerts; the rigid offset's force is internal to the body.
  const std::vector<Eigen::Matrix<double, 6, 1>> cut = CutJointReactions(model, state);
  std::vector<bool> replaced(model.n_nodes(), false);
  for (size_t c = 0; c < cut.size(); ++c) {
    const int k = model.cut_joints[c].joint.child, j = dofs.joint_of(k);
    // Held by a tree joint that is not a rigid body's offset (a support to the ground is).
    const bool tree_held = j >= 0 && (model.joints[j].type != JointType::kRigid || model.joints[j].parent == kGround);
    if (tree_held) continue;
    if (!replaced[k]) reactions[k].setZero();
    replaced[k] = true;
    reactions[k] += cut[c];
  }
  return reactions;
}

}  // namespace femb
