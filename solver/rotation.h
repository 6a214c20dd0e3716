// SO(3) helpers. Rotations are updated multiplicatively (R <- exp(dpi~) R for a spatial
// increment dpi); Euler angles are never integrated.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

#include "formats/skew.h"

namespace femb {

/// Rotation matrix exp(theta~) (Rodrigues).
Eigen::Matrix3d ExpSO3(const Eigen::Vector3d& theta);

/// Rotation vector theta with exp(theta~) = R, |theta| <= pi.
Eigen::Vector3d LogSO3(const Eigen::Matrix3d& R);

/// Inverse of the left Jacobian of SO(3): if R = exp(theta~) receives a spatial (left)
/// perturbation exp(dphi~) R, then d theta = J_l^-1(theta) dphi, with
/// J_l^-1 = 1 - theta~/2 + (1/|theta|^2 - (1 + cos|theta|) / (2 |theta| sin|theta|)) theta~^2.
/// Templated so that its derivative can be taken by forward-mode automatic differentiation.
template <typename S>
Eigen::Matrix<S, 3, 3> LeftJacobianInverse(const Eigen::Matrix<S, 3, 1>& theta) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  const S t2 = theta.squaredNorm();
  S c;
  if (t2 < S(1e-6)) {
    c = S(1.0 / 12.0) + t2 / S(720.0) + t2 * t2 / S(30240.0);
  } else {
    const S t = sqrt(t2);
    c = S(1) / t2 - (S(1) + cos(t)) / (S(2) * t * sin(t));
  }
  const Eigen::Matrix<S, 3, 3> W = Skew<S>(theta);
  return Eigen::Matrix<S, 3, 3>::Identity() - S(0.5) * W + c * W * W;
}

/// The rate (d/dt J_l(theta)) thetadot of the left Jacobian J_l = (J_l^-1)^-1 along
/// thetadot, applied to thetadot: -J_l (d/dt J_l^-1) J_l thetadot, exact (forward mode).
Eigen::Vector3d LeftJacobianRate(const Eigen::Vector3d& theta, const Eigen::Vector3d& theta_dot);

/// d/dtheta [J_l^-1(theta)^T v] (3 x 3), exact (forward-mode automatic differentiation).
Eigen::Matrix3d LeftJacobianInverseTransposeDerivative(const Eigen::Vector3d& theta, const Eigen::Vector3d& v);

}  // namespace femb
