// Joints between two nodes without Lagrange multipliers: the child node depends on its parent
// node and the joint's own coordinates z (DESIGN.md "Joints without Lagrange multipliers").
//   x_c = x_p + R_p (r0 + s a),  R_c = R_p exp(phi a~) Q0
// with a the joint axis and r0, Q0 the child's initial placement, all in the parent's frame.
// rigid: no coordinate; revolute: phi; prismatic: s; cylindrical: (s, phi); spherical: x_c
// follows the parent, the child's rotation has its own 3 coordinates (spatial increments);
// universal: (phi1, phi2) with R_c = R_p exp(phi1 a1~) exp(phi2 a2~) Q0 (a2 in the frame turned
// by phi1), omega_c = omega_p + g1 phi1dot + g2 phi2dot, g1 = R_p a1, g2 = R_p exp(phi1 a1~) a2.
// Spatial increments map linearly:  dq_c = A dq_p + B dz  with rho = x_c - x_p, g = R_p a:
//   A = [1, -rho~; 0, 1] (spherical: [1, -rho~; 0, 0]),  B = columns [g; 0] (s), [0; g] (phi),
//   [0; 1] (spherical rotation).
// Accelerations add the convective part c_c = A c_p + [omega_p x rhodot; 0] + Bdot zdot with
// rhodot = omega_p x rho + g sdot, gdot = omega_p x g.
#pragma once

#include <Eigen/Core>
#include <string>

#include "formats/kinds.h"

namespace femb {

/// The parent of a joint to the ground: a fixed node at the origin with world axes and no
/// coordinates (x_p = 0, R_p = 1, no Jacobian, no motion). A clamp is a rigid joint to it.
inline constexpr int kGround = -1;

struct NodeJoint {
  JointType type = JointType::kRigid;
  int child = -1, parent = kGround;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();   ///< unit, parent frame
  Eigen::Vector3d axis2 = Eigen::Vector3d::UnitY();  ///< universal: second axis, parent frame at phi1 = 0
  Eigen::Vector3d r0 = Eigen::Vector3d::Zero();      ///< child position, parent frame
  Eigen::Matrix3d Q0 = Eigen::Matrix3d::Identity();  ///< R_p^T R_c initially

  int n_coordinates() const;
  /// Index of the translation coordinate s (-1 if none) and of the angle phi (-1 if none).
  int s_index() const;
  int phi_index() const;
};

/// A support whose maps A, B are constant (a joint to the ground other than universal): no
/// convective acceleration, no geometric stiffness, no derivatives of either.
inline bool ConstantMaps(const NodeJoint& j) { return j.parent == kGround && j.type != JointType::kUniversal; }

/// A joint from the initial placements of both nodes; axes are global. To the ground (parent
/// kGround): x_p = 0, R_p = 1.
NodeJoint MakeNodeJoint(JointType type, int child, int parent, const Eigen::Vector3d& axis, const Eigen::Vector3d& x_p,
                        const Eigen::Matrix3d& R_p, const Eigen::Vector3d& x_c, const Eigen::Matrix3d& R_c,
                        const Eigen::Vector3d& axis2 = Eigen::Vector3d::UnitY());

/// Places the child from the parent and the joint coordinates z. For spherical joints the
/// child's rotation is its own and is left as it is.
void PlaceChild(const NodeJoint& j, const Eigen::Vector3d& x_p, const Eigen::Matrix3d& R_p, const Eigen::VectorXd& z,
                Eigen::Vector3d* x_c, Eigen::Matrix3d* R_c);

/// At most 3 joint coordinates (spherical): the joints' small matrices and vectors have a fixed
/// largest size and live on the stack (no heap allocation in a time step).
inline constexpr int kMaxJointCoordinates = 3;
using JointColumns = Eigen::Matrix<double, 6, Eigen::Dynamic, 0, 6, kMaxJointCoordinates>;
using JointVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxJointCoordinates, 1>;

/// The maps of dq_c = A dq_p + B dz at a configuration.
struct JointMaps {
  Eigen::Matrix<double, 6, 6> A;
  JointColumns B;
};
JointMaps ComputeJointMaps(const NodeJoint& j, const Eigen::Vector3d& x_p, const Eigen::Matrix3d& R_p,
                           const Eigen::Vector3d& x_c);

/// The maps of dq_c = A dq_p + B dz at a configuration (z: the joint's coordinates).
JointMaps ComputeJointMaps(const NodeJoint& j, const Eigen::Vector3d& x_p, const Eigen::Matrix3d& R_p,
                           const Eigen::Vector3d& x_c, const Eigen::VectorXd& z);

/// Convective acceleration of the child: c_c = A c_p + [omega_p x rhodot; 0] + Bdot zdot.
Eigen::Matrix<double, 6, 1> ChildConvective(const NodeJoint& j, const JointMaps& maps, const Eigen::Vector3d& x_p,
                                            const Eigen::Matrix3d& R_p, const Eigen::Vector3d& x_c,
                                            const Eigen::Matrix<double, 6, 1>& w_p,
                                            const Eigen::Ref<const Eigen::VectorXd>& zdot,
                                            const Eigen::Matrix<double, 6, 1>& c_p);

/// Derivative of (A^T f, B^T f) — the generalized force the child's force f = (F, M) puts on
/// the parent's increments and the joint coordinates — with respect to the parent's rotation
/// increment dpi_p and the joint coordinates, at fixed f. Returns the blocks:
///   dAf_dpi (6 x 3): d(A^T f)/d pi_p,   dAf_dz (6 x d): d(A^T f)/dz,
///   dBf_dpi (d x 3): d(B^T f)/d pi_p,   dBf_dz (d x d): d(B^T f)/dz (universal: g2 turns with phi1).
struct JointGeometric {
  Eigen::Matrix<double, 6, 3> dAf_dpi;
  JointColumns dAf_dz;
  Eigen::Matrix<double, Eigen::Dynamic, 3, 0, kMaxJointCoordinates, 3> dBf_dpi;
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxJointCoordinates, kMaxJointCoordinates> dBf_dz;
};
JointGeometric ComputeJointGeometric(const NodeJoint& j, const JointMaps& maps, const Eigen::Vector3d& x_p,
                                     const Eigen::Matrix3d& R_p, const Eigen::Vector3d& x_c,
                                     const Eigen::Matrix<double, 6, 1>& f);

}  // namespace femb
