// The joint tree: nodes that depend on parent nodes through NodeJoints (node_joint.h), their
// placement and node Jacobians composed down the tree, the joints' convective accelerations and
// their derivatives, the joints' geometric stiffness and the reactions they carry.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "solver/assembly/system_model.h"

namespace femb {

/// Spatial increment or velocity (dx, dpi) of node k from coordinate increments or rates; zero
/// for the ground (kGround).
Eigen::Matrix<double, 6, 1> NodeMotion(const SystemState& state, int k, const Eigen::VectorXd& dz);

/// A joint's parent as the tree sees it: node p's placement and Jacobian, or for the ground
/// (kGround) the origin, world axes and no coordinates.
struct ParentNode {
  const Eigen::Vector3d& x;
  const Eigen::Matrix3d& R;
  const NodeJacobian& J;
};
ParentNode ParentOf(const SystemState& state, int p);

/// Node accelerations J_k Wdot + convective terms of the joints.
std::vector<Eigen::Matrix<double, 6, 1>> NodeAccelerations(const SystemModel& model, const DofMap& dofs,
                                                           const SystemState& state, const Eigen::VectorXd& W,
                                                           const Eigen::VectorXd& Wdot);
/// The same into `acc` (its storage reused).
void NodeAccelerations(const SystemModel& model, const DofMap& dofs, const SystemState& state, const Eigen::VectorXd& W,
                       const Eigen::VectorXd& Wdot, std::vector<Eigen::Matrix<double, 6, 1>>& acc,
                       SystemScratch* scratch = nullptr);

/// The derivative of the joints' convective accelerations (NodeAccelerations) with respect to
/// the coordinate velocities W, per node as sparse columns (coordinate, 6-vector); empty for
/// nodes without joints above them. Quadratic in W: the Coriolis and centripetal terms of a
/// chain of joints with offsets, whose share d f_in / dW = M_b dc/dW belongs in the iteration
/// matrix's C (without it Newton converged linearly on a rigid four-bar, 2 iterations a step).
/// Into `dc` (its storage reused).
void ConvectiveVelocityDerivative(const SystemModel& model, const DofMap& dofs, const SystemState& state,
                                  const Eigen::VectorXd& W, std::vector<NodeJacobian>& dc);

/// The derivative of the node accelerations J_k(q) Wdot + c_k(q, W) (NodeAccelerations) with
/// respect to the coordinates at fixed W and Wdot, per node as sparse columns; empty for nodes
/// without joints above them; down the tree with the joints' maps (no state copies). Its share
/// M_b d(acc)/dq belongs in the iteration matrix's K (on a rigid four-bar it was half of K).
/// Into `out` (its storage reused).
void NodeAccelerationConfigurationDerivative(const SystemModel& model, const DofMap& dofs, const SystemState& state,
                                             const Eigen::VectorXd& W, const Eigen::VectorXd& Wdot,
                                             std::vector<NodeJacobian>& out, SystemScratch* scratch = nullptr);

/// Places the dependent nodes from their parents and recomputes the node Jacobians.
void UpdateKinematics(const SystemModel& model, const DofMap& dofs, SystemState& state);

/// Forces in node space (residual sense: applied minus internal) and their derivatives,
/// mapped to the coordinates by the node Jacobians, plus the joints' geometric stiffness.
struct NodeForces {
  std::vector<Eigen::Matrix<double, 6, 1>> f;
  void Add(int k, const Eigen::Matrix<double, 6, 1>& v) { f[k] += v; }
};
NodeForces ZeroNodeForces(const SystemModel& model);
/// tangent -= d(sum_k J_k^T f_k)/dz at fixed f (the joint maps' configuration dependence).
void AddJointGeometricStiffness(const SystemModel& model, const DofMap& dofs, const SystemState& state,
                                const NodeForces& forces, Triplets& tangent, SystemScratch* scratch = nullptr);

/// Support and joint reactions at a converged state: for every node held by something (a
/// support: a joint to the ground; or a parent node through a joint), the force
/// and moment (global axes, moment about the node) that the support or the parent exerts on the
/// node and all that hangs from it: R_k = -t_k, t_k = f_k + sum over child joints A_c^T t_c, f
/// the node forces of the assembly (applied minus internal and inertia forces). For a prescribed
/// joint coordinate the reaction includes the drive: e.g. a driven revolute's moment about its
/// axis is the driving torque. A node that is the child of cut joints and held otherwise by
/// nothing or by a rigid joint (a rigid body's point): the cut joints' reactions
/// (CutJointReactions). Other nodes: zero.
std::vector<Eigen::Matrix<double, 6, 1>> JointReactions(const SystemModel& model, const DofMap& dofs,
                                                        const SystemState& state, const NodeForces& forces);

}  // namespace femb
