#include "solver/forces/spring_damper.h"

#include <cmath>

namespace femb {

SpringDamperForces EvaluateSpringDamper(const SpringDamper& s, const Eigen::Vector3d& xa, const Eigen::Vector3d& xb,
                                        const Eigen::Vector3d& va, const Eigen::Vector3d& vb) {
  SpringDamperForces out;
  const Eigen::Vector3d d = xb - xa, v = vb - va;
  const double l = d.norm();
  const Eigen::Vector3d e = d / l;
  const double ldot = e.dot(v);
  const double N = s.stiffness * (l - s.free_length) + s.damping * ldot;
  out.f << N * e, -N * e;
  out.energy = 0.5 * s.stiffness * (l - s.free_length) * (l - s.free_length);
  // d(N e)/d x_b = e dN/dx_b + N de/dx_b; de/dx_b = P / l with P = 1 - e e^T;
  // dN/dx_b = k e^T + c v^T P / l; dN/dv_b = c e^T.
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - e * e.transpose();
  const Eigen::Matrix3d dfa_dxb = e * (s.stiffness * e.transpose() + s.damping * v.transpose() * P / l) + N * P / l;
  const Eigen::Matrix3d dfa_dvb = s.damping * e * e.transpose();
  // f_a depends on x_b - x_a: d/dx_a = -d/dx_b; f_b = -f_a. K = -df/dx.
  out.K << dfa_dxb, -dfa_dxb, -dfa_dxb, dfa_dxb;
  out.C << dfa_dvb, -dfa_dvb, -dfa_dvb, dfa_dvb;
  return out;
}

}  // namespace femb
