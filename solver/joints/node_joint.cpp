#include "solver/joints/node_joint.h"

#include <Eigen/Geometry>
#include <stdexcept>

#include "solver/rotation.h"

namespace femb {

int NodeJoint::n_coordinates() const {
  switch (type) {
    case JointType::kRigid:
      return 0;
    case JointType::kRevolute:
      return 1;
    case JointType::kPrismatic:
      return 1;
    case JointType::kCylindrical:
      return 2;
    case JointType::kSpherical:
      return 3;
    case JointType::kUniversal:
      return 2;
  }
  return 0;
}

int NodeJoint::s_index() const { return (type == JointType::kPrismatic || type == JointType::kCylindrical) ? 0 : -1; }

int NodeJoint::phi_index() const {
  if (type == JointType::kRevolute) return 0;
  if (type == JointType::kCylindrical) return 1;
  return -1;
}

NodeJoint MakeNodeJoint(JointType type, int child, int parent, const Eigen::Vector3d& axis, const Eigen::Vector3d& x_p,
                        const Eigen::Matrix3d& R_p, const Eigen::Vector3d& x_c, const Eigen::Matrix3d& R_c,
                        const Eigen::Vector3d& axis2) {
  NodeJoint j;
  j.type = type;
  j.child = child;
  j.parent = parent;
  j.axis = R_p.transpose() * axis.normalized();
  j.axis2 = R_p.transpose() * axis2.normalized();
  j.r0 = R_p.transpose() * (x_c - x_p);
  j.Q0 = R_p.transpose() * R_c;
  return j;
}

void PlaceChild(const NodeJoint& j, const Eigen::Vector3d& x_p, const Eigen::Matrix3d& R_p, const Eigen::VectorXd& z,
                Eigen::Vector3d* x_c, Eigen::Matrix3d* R_c) {
  const double s = j.s_index() >= 0 ? z[j.s_index()] : 0.0;
  const double phi = j.phi_index() >= 0 ? z[j.phi_index()] : 0.0;
  *x_c = x_p + R_p * (j.r0 + s * j.axis);
  if (j.type == JointType::kUniversal) {
    *R_c = R_p * ExpSO3(z[0] * j.axis) * ExpSO3(z[1] * j.axis2) * j.Q0;
  } else if (j.type != JointType::kSpherical) {
    *R_c = R_p * ExpSO3(phi * j.axis) * j.Q0;
  }
}

JointMaps ComputeJointMaps(const NodeJoint& j, const Eigen::Vector3d& x_p, const Eigen::Matrix3d& R_p,
                           const Eigen::Vector3d& x_c, const Eigen::VectorXd& z) {
  JointMaps m = ComputeJointMaps(j, x_p, R_p, x_c);
  if (j.type == JointType::kUniversal) {
    m.B.col(0).tail<3>() = R_p * j.axis;
    m.B.col(1).tail<3>() = R_p * ExpSO3(z[0] * j.axis) * j.axis2;
  }
  return m;
}

JointMaps ComputeJointMaps(const NodeJoint& j, const Eigen::Vector3d& x_p, const Eigen::Matrix3d& R_p,
                           const Eigen::Vector3d& x_c) {
  JointMaps m;
  const Eigen::Vector3d rho = x_c - x_p, g = R_p * j.axis;
  m.A.setIdentity();
  m.A.block<3, 3>(0, 3) = -Skew<double>(rho);
  if (j.type == JointType::kSpherical) m.A.block<3, 3>(3, 3).setZero();
  m.B.setZero(6, j.n_coordinates());
  if (j.s_index() >= 0) m.B.col(j.s_index()).head<3>() = g;
  if (j.phi_index() >= 0) m.B.col(j.phi_index()).tail<3>() = g;
  if (j.type == JointType::kSpherical) m.B.bottomRows<3>().setIdentity();
  return m;
}

Eigen::Matrix<double, 6, 1> ChildConvective(const NodeJoint& j, const JointMaps& maps, const Eigen::Vector3d& x_p,
                                            const Eigen::Matrix3d& R_p, const Eigen::Vector3d& x_c,
                                            const Eigen::Matrix<double, 6, 1>& w_p,
                                            const Eigen::Ref<const Eigen::VectorXd>& zdot,
                                            const Eigen::Matrix<double, 6, 1>& c_p) {
  const Eigen::Vector3d rho = x_c - x_p, g = R_p * j.axis, omega_p = w_p.tail<3>();
  const double sdot = j.s_index() >= 0 ? zdot[j.s_index()] : 0.0;
  const double phidot = j.phi_index() >= 0 ? zdot[j.phi_index()] : 0.0;
  const Eigen::Vector3d rhodot = omega_p.cross(rho) + sdot * g;
  const Eigen::Vector3d gdot = omega_p.cross(g);
  Eigen::Matrix<double, 6, 1> c = maps.A * c_p;
  c.head<3>() += omega_p.cross(rhodot) + sdot * gdot;
  c.tail<3>() += phidot * gdot;
  if (j.type == JointType::kUniversal) {
    const Eigen::Vector3d g1 = maps.B.col(0).tail<3>(), g2 = maps.B.col(1).tail<3>();
    c.tail<3>() += zdot[0] * omega_p.cross(g1) + zdot[1] * (omega_p.cross(g2) + zdot[0] * g1.cross(g2));
  }
  return c;
}

JointGeometric ComputeJointGeometric(const NodeJoint& j, const JointMaps& maps, const Eigen::Vector3d& x_p,
                                     const Eigen::Matrix3d& R_p, const Eigen::Vector3d& x_c,
                                     const Eigen::Matrix<double, 6, 1>& f) {
  const Eigen::Vector3d rho = x_c - x_p, g = R_p * j.axis, F = f.head<3>(), M = f.tail<3>();
  const int d = j.n_coordinates();
  JointGeometric out;
  out.dAf_dpi.setZero();
  out.dAf_dz.setZero(6, d);
  out.dBf_dpi.setZero(d, 3);
  out.dBf_dz.setZero(d, d);
  // A^T f = [F; rho x F (+ M)]: d(rho x F) = -F~ d rho, d rho = -rho~ d pi_p + g ds.
  out.dAf_dpi.bottomRows<3>() = Skew<double>(F) * Skew<double>(rho);
  if (j.s_index() >= 0) out.dAf_dz.col(j.s_index()).tail<3>() = -Skew<double>(F) * g;
  // B^T f: g . F (s), g . M (phi); d g = -g~ d pi_p, so d(g . v)/d pi_p = (g x v)^T.
  if (j.s_index() >= 0) out.dBf_dpi.row(j.s_index()) = g.cross(F).transpose();
  if (j.phi_index() >= 0) out.dBf_dpi.row(j.phi_index()) = g.cross(M).transpose();
  if (j.type == JointType::kUniversal) {
    const Eigen::Vector3d g1 = maps.B.col(0).tail<3>(), g2 = maps.B.col(1).tail<3>();
    out.dBf_dpi.row(0) = g1.cross(M).transpose();
    out.dBf_dpi.row(1) = g2.cross(M).transpose();
    out.dBf_dz(1, 0) = g1.cross(g2).dot(M);  // g2 turns about g1 with phi1
  }
  return out;
}

}  // namespace femb
