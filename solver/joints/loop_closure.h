// Joints that close kinematic loops. The tree joints of the scene make child nodes
// functions of parent nodes (node_joint.h) and need no multipliers; a joint that would close a
// loop of that tree (a node with two parents, a cycle) is cut: its child keeps its own
// coordinates and the joint becomes algebraic equations g(q) = 0 with Lagrange multipliers
// lambda, added to the equations of motion as -G^T lambda (G = dg/dq).
//
// The equations of a cut joint of axis a, with b1, b2 completing a right-handed orthonormal
// frame (a, b1, b2) in the parent's frame, r0 and Q0 the child's initial placement there
// (node_joint.h). U_e = R_p e is a vector of the parent, V_f = R_c Q0^T f one of the child (both
// equal R_p e initially), d = x_c - x_p:
//   position along e:   g = U_e . d - e . r0                 (zero offset across e)
//   rotation (e, f):    g = U_e . V_f - e . f                (dot-product constraint)
// rigid:       position a, b1, b2; rotation (b1, a), (b2, a), (b1, b2)           6 equations
// revolute:    position a, b1, b2; rotation (b1, a), (b2, a)                       5
// prismatic:   position b1, b2;    rotation (b1, a), (b2, a), (b1, b2)             5
// cylindrical: position b1, b2;    rotation (b1, a), (b2, a)                       4
// spherical:   position a, b1, b2                                                  3
// universal:   position a, b1, b2; rotation (a1, a2) (the cross stays a cross)     4
// Linearized about V = U: (b1, a) and (b2, a) hold the rotation components along b2 and b1,
// (b1, b2) the one along a; so the equations are independent.
//
// Variations with the spatial increments (dx, dpi) of the nodes (R <- exp(dpi~) R), in the
// order dq = (dx_p, dpi_p, dx_c, dpi_c): dU = dpi_p x U, dV = dpi_c x V, dd = dx_c - dx_p:
//   position:  G = [-U^T, (U x d)^T, U^T, 0]
//   rotation:  G = [0, (U x V)^T, 0, -(U x V)^T]
// and the derivative of G^T lambda (the multipliers' geometric stiffness) with
// d(-U) = U~ dpi_p, d(U x d) = d~ U~ dpi_p + U~ (dx_c - dx_p), d(U x V) = V~ U~ dpi_p - U~ V~ dpi_c.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "solver/joints/node_joint.h"

namespace femb {

/// A joint closing a loop: the joint (child, parent, axes and initial placement as for a tree
/// joint) and the equations kept (indices into the type's full set above; redundant ones of an
/// over-constrained mechanism are dropped, see DropRedundantEquations in loop_constraints.h).
struct CutJoint {
  NodeJoint joint;
  std::string name;            ///< for messages, e.g. "revolute joint between nodes 'C' and 'D'"
  std::vector<int> equations;  ///< kept equations, ascending
};

/// Number of equations in the full set of a joint type (6 minus its freedoms).
int ConstraintCount(JointType type);

/// A cut joint's full set of equations at a configuration: values g and their derivative with
/// respect to the nodes' spatial increments, G (m x 12: dx_p, dpi_p, dx_c, dpi_c).
/// At most 6 equations: fixed-capacity storage, so that evaluating one allocates nothing.
using ConstraintValues = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>;
struct ConstraintBlock {
  ConstraintValues g;
  Eigen::Matrix<double, Eigen::Dynamic, 12, 0, 6, 12> G;
  std::array<bool, 6> position{};  ///< per equation: a position (length), else a rotation (dot product)
};
ConstraintBlock EvaluateConstraint(const NodeJoint& j, const Eigen::Vector3d& x_p, const Eigen::Matrix3d& R_p,
                                   const Eigen::Vector3d& x_c, const Eigen::Matrix3d& R_c);

/// d(G^T lambda)/dq (12 x 12) for multipliers lambda of the full set (m).
Eigen::Matrix<double, 12, 12> ConstraintHessian(const NodeJoint& j, const Eigen::Vector3d& x_p,
                                                const Eigen::Matrix3d& R_p, const Eigen::Vector3d& x_c,
                                                const Eigen::Matrix3d& R_c, const ConstraintValues& lambda);

/// A cut revolute, prismatic, cylindrical or universal joint's coordinates as the tree joint
/// would have them (node_joint.h): s = a . (R_p^T (x_c - x_p) - r0), phi = the angle of
/// R_p^T R_c Q0^T about a in (-pi, pi] (atan2 of its action on b1); universal: the two angles of
/// R_p^T R_c Q0^T = exp(z0 a) exp(z1 b), each in (-pi, pi]. Empty for other types. For `joint`
/// probes.
Eigen::VectorXd CutJointCoordinates(const NodeJoint& j, const Eigen::Vector3d& x_p, const Eigen::Matrix3d& R_p,
                                    const Eigen::Vector3d& x_c, const Eigen::Matrix3d& R_c);

/// What equation i of the joint's full set holds back, for messages: "translation along the
/// axis", "translation along (0, 1, 0)" (the parent's axes at t = 0), "tilt of the axis", ...
std::string ConstraintName(const NodeJoint& j, int i);

}  // namespace femb
