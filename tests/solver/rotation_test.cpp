// SO(3) helpers (solver/rotation.h) against independent references: Eigen's AngleAxis for the
// exponential, exp(log R) = R up to the angle pi, and central finite differences of the
// exponential and logarithm for the left Jacobian, its rate and its transpose's derivative.
#include "solver/rotation.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <vector>

namespace femb {
namespace {

std::vector<Eigen::Vector3d> Angles() {
  // Small (the series branches), moderate, large and near pi, along skew axes.
  const Eigen::Vector3d axis = Eigen::Vector3d(0.3, -0.5, 0.81).normalized();
  const Eigen::Vector3d other = Eigen::Vector3d(-0.7, 0.1, 0.2).normalized();
  return {1e-9 * axis, 1e-6 * axis, 3e-4 * other, 0.2 * axis, 1.3 * other, 2.9 * axis, (M_PI - 1e-7) * other};
}

TEST(Rotation, ExponentialIsEigensAngleAxisAndOrthonormal) {
  for (const Eigen::Vector3d& theta : Angles()) {
    const Eigen::Matrix3d R = ExpSO3(theta);
    const double t = theta.norm();
    const Eigen::Matrix3d reference = Eigen::AngleAxisd(t, theta / t).toRotationMatrix();
    EXPECT_LT((R - reference).norm(), 1e-14) << "theta " << theta.transpose();
    EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 1e-14);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-14);
  }
  EXPECT_EQ(ExpSO3(Eigen::Vector3d::Zero()), Eigen::Matrix3d::Identity());
}

TEST(Rotation, LogarithmInvertsTheExponentialUpToPi) {
  for (const Eigen::Vector3d& theta : Angles()) {
    const Eigen::Vector3d back = LogSO3(ExpSO3(theta));
    // Near pi the axis comes from the symmetric part: sqrt(eps)-accurate in the angle's
    // direction, exact in the rotation it gives.
    const double tol = theta.norm() > 3.0 ? 1e-7 : 1e-12 * std::max(1.0, theta.norm());
    EXPECT_LT((back - theta).norm(), tol) << "theta " << theta.transpose();
    EXPECT_LT((ExpSO3(back) - ExpSO3(theta)).norm(), 1e-12);
  }
  // Exactly pi: either sign of the axis is the same rotation.
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 2, 2) / 3.0;
  const Eigen::Vector3d back = LogSO3(Eigen::AngleAxisd(M_PI, axis).toRotationMatrix());
  EXPECT_NEAR(back.norm(), M_PI, 1e-12);
  EXPECT_LT(std::min((back - M_PI * axis).norm(), (back + M_PI * axis).norm()), 1e-7);
}

// d theta = J_l^-1(theta) dphi for a spatial perturbation R -> exp(dphi~) R: the columns of
// J_l^-1 from central differences of log(exp(eps e_j~) exp(theta~)).
TEST(Rotation, LeftJacobianInverseMapsSpatialPerturbations) {
  const double eps = 1e-6;
  for (const Eigen::Vector3d& theta : Angles()) {
    if (theta.norm() > 3.0) continue;  // the log's branch cut at pi
    const Eigen::Matrix3d R = ExpSO3(theta);
    Eigen::Matrix3d fd;
    for (int j = 0; j < 3; ++j) {
      const Eigen::Vector3d e = eps * Eigen::Vector3d::Unit(j);
      fd.col(j) = (LogSO3(ExpSO3(e) * R) - LogSO3(ExpSO3(-e) * R)) / (2 * eps);
    }
    EXPECT_LT((LeftJacobianInverse<double>(theta) - fd).norm(), 1e-8) << "theta " << theta.transpose();
  }
  // The small-angle series and the closed form meet at |theta|^2 = 1e-6.
  const Eigen::Vector3d dir = Eigen::Vector3d(1, -2, 0.5).normalized();
  const Eigen::Matrix3d below = LeftJacobianInverse<double>((1e-3 - 1e-12) * dir);
  const Eigen::Matrix3d above = LeftJacobianInverse<double>((1e-3 + 1e-12) * dir);
  EXPECT_LT((below - above).norm(), 1e-11);
}

// (d/dt J_l(theta(t))) thetadot with J_l = (J_l^-1)^-1, against central differences in t.
TEST(Rotation, LeftJacobianRateIsTheDerivativeAlongThePath) {
  const double eps = 1e-6;
  const Eigen::Vector3d rate(0.4, -1.1, 0.7);
  for (const Eigen::Vector3d& theta : Angles()) {
    if (theta.norm() > 3.0) continue;
    const Eigen::Matrix3d plus = LeftJacobianInverse<double>(Eigen::Vector3d(theta + eps * rate)).inverse();
    const Eigen::Matrix3d minus = LeftJacobianInverse<double>(Eigen::Vector3d(theta - eps * rate)).inverse();
    const Eigen::Vector3d fd = (plus - minus) / (2 * eps) * rate;
    EXPECT_LT((LeftJacobianRate(theta, rate) - fd).norm(), 1e-8 * std::max(1.0, fd.norm()))
        << "theta " << theta.transpose();
  }
}

TEST(Rotation, LeftJacobianInverseTransposeDerivativeMatchesDifferences) {
  const double eps = 1e-6;
  const Eigen::Vector3d v(2.0, -0.3, 1.1);
  for (const Eigen::Vector3d& theta : Angles()) {
    if (theta.norm() > 3.0) continue;
    Eigen::Matrix3d fd;
    for (int j = 0; j < 3; ++j) {
      const Eigen::Vector3d e = eps * Eigen::Vector3d::Unit(j);
      fd.col(j) = (LeftJacobianInverse<double>(Eigen::Vector3d(theta + e)).transpose() * v -
                   LeftJacobianInverse<double>(Eigen::Vector3d(theta - e)).transpose() * v) /
                  (2 * eps);
    }
    EXPECT_LT((LeftJacobianInverseTransposeDerivative(theta, v) - fd).norm(), 1e-8) << "theta " << theta.transpose();
  }
}

}  // namespace
}  // namespace femb
