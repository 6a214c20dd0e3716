#include "solver/rotation.h"

#include <unsupported/Eigen/AutoDiff>

namespace femb {

Eigen::Matrix3d ExpSO3(const Eigen::Vector3d& theta) {
  const double t2 = theta.squaredNorm();
  const Eigen::Matrix3d W = Skew<double>(theta);
  double a, b;
  if (t2 < 1e-10) {
    a = 1.0 - t2 / 6.0;
    b = 0.5 - t2 / 24.0;
  } else {
    const double t = std::sqrt(t2);
    a = std::sin(t) / t;
    b = (1.0 - std::cos(t)) / t2;
  }
  return Eigen::Matrix3d::Identity() + a * W + b * W * W;
}

Eigen::Vector3d LogSO3(const Eigen::Matrix3d& R) {
  const double c = std::clamp(0.5 * (R.trace() - 1.0), -1.0, 1.0);
  const double t = std::acos(c);
  const Eigen::Vector3d w(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  if (t < 1e-6) return 0.5 * (1.0 + t * t / 6.0) * w;
  if (M_PI - t > 1e-6) return t / (2.0 * std::sin(t)) * w;
  // Near pi: axis from the symmetric part (R's antisymmetric part sin(t) a~ would tilt it by
  // ~(pi - t)), sign from w.
  const Eigen::Matrix3d B = 0.5 * (0.5 * (R + R.transpose()) + Eigen::Matrix3d::Identity());
  int k;
  B.diagonal().maxCoeff(&k);
  Eigen::Vector3d axis = B.col(k) / std::sqrt(std::max(B(k, k), 1e-300));
  axis.normalize();
  if (axis.dot(w) < 0) axis = -axis;
  // The angle from atan2(sin, cos): acos of c = -1 + (pi - t)^2 / 2 keeps only sqrt(eps) of it.
  return std::atan2(0.5 * w.norm(), c) * axis;
}

Eigen::Matrix3d LeftJacobianInverseTransposeDerivative(const Eigen::Vector3d& theta, const Eigen::Vector3d& v) {
  using AD = Eigen::AutoDiffScalar<Eigen::Vector3d>;
  Eigen::Matrix<AD, 3, 1> t;
  for (int i = 0; i < 3; ++i) t[i] = AD(theta[i], 3, i);
  const Eigen::Matrix<AD, 3, 3> Jinv = LeftJacobianInverse<AD>(t);
  const Eigen::Matrix<AD, 3, 1> y = Jinv.transpose() * v.cast<AD>();
  Eigen::Matrix3d G;
  for (int i = 0; i < 3; ++i) G.row(i) = y[i].derivatives().transpose();
  return G;
}

Eigen::Vector3d LeftJacobianRate(const Eigen::Vector3d& theta, const Eigen::Vector3d& theta_dot) {
  using AD = Eigen::AutoDiffScalar<Eigen::Matrix<double, 1, 1>>;
  Eigen::Matrix<AD, 3, 1> t;
  for (int i = 0; i < 3; ++i) t[i] = AD(theta[i], Eigen::Matrix<double, 1, 1>(theta_dot[i]));
  const Eigen::Matrix<AD, 3, 3> Jinv = LeftJacobianInverse<AD>(t);
  Eigen::Matrix3d value, rate;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) value(i, j) = Jinv(i, j).value(), rate(i, j) = Jinv(i, j).derivatives()[0];
  const Eigen::Matrix3d J = value.inverse();
  return -J * (rate * (J * theta_dot));
}

}  // namespace femb
