#include "solver/joints/loop_closure.h"

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdio>
#include <initializer_list>

#include "solver/rotation.h"

namespace femb {

namespace {

// One equation of the full set: a position along e, or the dot product of the parent's e and
// the child's f.
struct Equation {
  bool position;
  Eigen::Vector3d e, f;
};

// (a, b1, b2) right-handed and orthonormal, b1 from the coordinate axis least aligned with a.
void CrossDirections(const Eigen::Vector3d& a, Eigen::Vector3d& b1, Eigen::Vector3d& b2) {
  Eigen::Index least = 0;
  a.cwiseAbs().minCoeff(&least);
  b1 = a.cross(Eigen::Vector3d::Unit(least)).normalized();
  b2 = a.cross(b1);
}

// A joint's full set of equations (at most 6; fixed storage, no allocation).
struct EquationSet {
  std::array<Equation, 6> eq;
  int n = 0;
  EquationSet(std::initializer_list<Equation> list) {
    for (const Equation& e : list) eq[size_t(n++)] = e;
  }
  int size() const { return n; }
  const Equation& operator[](size_t i) const { return eq[i]; }
};

EquationSet Equations(const NodeJoint& j) {
  const Eigen::Vector3d a = j.axis.normalized();
  Eigen::Vector3d b1, b2;
  CrossDirections(a, b1, b2);
  const Eigen::Vector3d none = Eigen::Vector3d::Zero();
  const Equation pa{true, a, none}, pb1{true, b1, none}, pb2{true, b2, none};
  const Equation r1{false, b1, a}, r2{false, b2, a}, r3{false, b1, b2};
  switch (j.type) {
    case JointType::kRigid:
      return {pa, pb1, pb2, r1, r2, r3};
    case JointType::kRevolute:
      return {pa, pb1, pb2, r1, r2};
    case JointType::kPrismatic:
      return {pb1, pb2, r1, r2, r3};
    case JointType::kCylindrical:
      return {pb1, pb2, r1, r2};
    case JointType::kSpherical:
      return {pa, pb1, pb2};
    case JointType::kUniversal:
      return {pa, pb1, pb2, Equation{false, a, j.axis2.normalized()}};
  }
  return {};
}

}  // namespace

int ConstraintCount(JointType type) {
  NodeJoint j;
  j.type = type;
  return Equations(j).size();
}

ConstraintBlock EvaluateConstraint(const NodeJoint& j, const Eigen::Vector3d& x_p, const Eigen::Matrix3d& R_p,
                                   const Eigen::Vector3d& x_c, const Eigen::Matrix3d& R_c) {
  const EquationSet eqs = Equations(j);
  const int m = eqs.size();
  ConstraintBlock out;
  out.g.resize(m);
  out.G.setZero(m, 12);
  const Eigen::Vector3d d = x_c - x_p;
  const Eigen::Matrix3d R_cQ = R_c * j.Q0.transpose();
  for (int i = 0; i < m; ++i) {
    const Eigen::Vector3d U = R_p * eqs[size_t(i)].e;
    out.position[size_t(i)] = eqs[size_t(i)].position;
    if (eqs[size_t(i)].position) {
      out.g[i] = U.dot(d) - eqs[size_t(i)].e.dot(j.r0);
      out.G.block<1, 3>(i, 0) = -U.transpose();
      out.G.block<1, 3>(i, 3) = U.cross(d).transpose();
      out.G.block<1, 3>(i, 6) = U.transpose();
    } else {
      const Eigen::Vector3d V = R_cQ * eqs[size_t(i)].f;
      out.g[i] = U.dot(V) - eqs[size_t(i)].e.dot(eqs[size_t(i)].f);
      out.G.block<1, 3>(i, 3) = U.cross(V).transpose();
      out.G.block<1, 3>(i, 9) = -U.cross(V).transpose();
    }
  }
  return out;
}

Eigen::Matrix<double, 12, 12> ConstraintHessian(const NodeJoint& j, const Eigen::Vector3d& x_p,
                                                const Eigen::Matrix3d& R_p, const Eigen::Vector3d& x_c,
                                                const Eigen::Matrix3d& R_c, const ConstraintValues& lambda) {
  const EquationSet eqs = Equations(j);
  Eigen::Matrix<double, 12, 12> H = Eigen::Matrix<double, 12, 12>::Zero();
  const Eigen::Vector3d d = x_c - x_p;
  const Eigen::Matrix3d R_cQ = R_c * j.Q0.transpose();
  for (size_t i = 0; i < size_t(eqs.size()); ++i) {
    const double l = lambda[Eigen::Index(i)];
    if (l == 0.0) continue;
    const Eigen::Vector3d U = R_p * eqs[i].e;
    const Eigen::Matrix3d U_ = Skew<double>(U);
    if (eqs[i].position) {
      // rows dx_p (-U), dpi_p (U x d), dx_c (U)
      H.block<3, 3>(0, 3) += l * U_;
      H.block<3, 3>(3, 0) -= l * U_;
      H.block<3, 3>(3, 3) += l * Skew<double>(d) * U_;
      H.block<3, 3>(3, 6) += l * U_;
      H.block<3, 3>(6, 3) -= l * U_;
    } else {
      // rows dpi_p (U x V), dpi_c (-(U x V))
      const Eigen::Matrix3d V_ = Skew<double>(Eigen::Vector3d(R_cQ * eqs[i].f));
      const Eigen::Matrix3d dp = V_ * U_, dc = -U_ * V_;
      H.block<3, 3>(3, 3) += l * dp;
      H.block<3, 3>(3, 9) += l * dc;
      H.block<3, 3>(9, 3) -= l * dp;
      H.block<3, 3>(9, 9) -= l * dc;
    }
  }
  return H;
}

Eigen::VectorXd CutJointCoordinates(const NodeJoint& j, const Eigen::Vector3d& x_p, const Eigen::Matrix3d& R_p,
                                    const Eigen::Vector3d& x_c, const Eigen::Matrix3d& R_c) {
  if (j.type == JointType::kUniversal) {
    // rel = exp(z0 a) exp(z1 b), a the parent's axis, b the cross's second axis (b . a = 0):
    // rel b = exp(z0 a) b turns b about a by z0; exp(-z0 a) rel a = exp(z1 b) a turns a about b.
    const Eigen::Vector3d a = j.axis.normalized(), b = j.axis2.normalized();
    const Eigen::Matrix3d rel = R_p.transpose() * R_c * j.Q0.transpose();
    Eigen::VectorXd z(2);
    const Eigen::Vector3d rb = rel * b;
    z[0] = std::atan2(a.cross(b).dot(rb), b.dot(rb));
    const Eigen::Vector3d ra = ExpSO3(Eigen::Vector3d(-z[0] * a)) * rel * a;
    z[1] = std::atan2(b.cross(a).dot(ra), a.dot(ra));
    return z;
  }
  if (j.type != JointType::kRevolute && j.type != JointType::kPrismatic && j.type != JointType::kCylindrical) {
    return Eigen::VectorXd();
  }
  const Eigen::Vector3d a = j.axis.normalized();
  Eigen::Vector3d b1, b2;
  CrossDirections(a, b1, b2);
  Eigen::VectorXd z(j.n_coordinates());
  if (j.s_index() >= 0) z[j.s_index()] = a.dot(R_p.transpose() * (x_c - x_p) - j.r0);
  if (j.phi_index() >= 0) {
    const Eigen::Vector3d turned = R_p.transpose() * R_c * j.Q0.transpose() * b1;
    z[j.phi_index()] = std::atan2(b2.dot(turned), b1.dot(turned));
  }
  return z;
}

std::string ConstraintName(const NodeJoint& j, int i) {
  const EquationSet eqs = Equations(j);
  if (i < 0 || i >= eqs.size()) return "equation " + std::to_string(i);
  const Equation& q = eqs[size_t(i)];
  if (j.type == JointType::kUniversal && !q.position) return "rotation about the normal of the cross";
  const bool axial = j.type != JointType::kRigid && j.type != JointType::kSpherical;
  // Linearized, position e holds the translation along e, rotation (e, f) the rotation about f x e.
  const Eigen::Vector3d v = q.position ? q.e : Eigen::Vector3d(q.f.cross(q.e));
  const bool along_axis = v.normalized().isApprox(j.axis.normalized()) || v.normalized().isApprox(-j.axis.normalized());
  if (axial && along_axis) return q.position ? "translation along the axis" : "rotation about the axis";
  char buffer[160];
  std::snprintf(buffer, sizeof buffer, "%s (%.3g, %.3g, %.3g) of the parent's axes",
                q.position ? "translation along" : "rotation about", v.x() + 0.0, v.y() + 0.0, v.z() + 0.0);
  return buffer;
}

}  // namespace femb
