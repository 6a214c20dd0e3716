// The inertia load factors of the floating frame and the products of the load cases' stiffness.
#include "solver/body/inertia_stiffening.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "solver/body/superelement_body.h"
#include "solver/rotation.h"

namespace femb {

const Eigen::MatrixXd& SigmaProducts(const SuperelementBody& body, BodyData& d) {
  if (!d.has_sigma_q) {
    const int n = body.n_coordinates();
    // The stacked product K_sigma q (12 n) is the n x 12 matrix column by column.
    d.sigma_q.resize(n, kInertiaLoadCaseCount);
    Eigen::Map<Eigen::VectorXd>(d.sigma_q.data(), Eigen::Index(n) * kInertiaLoadCaseCount).noalias() =
        body.K_sigma_stack_ * d.q;
    d.has_sigma_q = true;
  }
  return d.sigma_q;
}

void InertiaLoads(const SuperelementBody& body, BodyData& d, const BodyVelocity& w, const BodyVelocity& wdot,
                  const Eigen::Vector3d& gravity, InertiaLoadFactors& out) {
  const int n = body.n_coordinates();
  out.d_w.setZero(12, n);
  out.d_wdot.setZero(12, n);
  const Eigen::VectorXd& q = d.q;
  const BodyKinematics& kin = d.kin;
  const FrameSolution& frame = d.frame;
  // Z Rbar^T: node vectors to frame axes, then the frame's part.
  Eigen::MatrixXd& ZR = d.scratch.n6a;
  ZR = kin.Z;
  const Eigen::Matrix3d Rt = frame.R.transpose();
  for (int a = 0; a < 2 * body.n_nodes_; ++a) ZR.middleCols<3>(3 * a).noalias() = kin.Z.middleCols<3>(3 * a) * Rt;
  const Eigen::Vector3d omega = ZR.bottomRows<3>() * w;
  const auto d_omega = ZR.bottomRows<3>();  // 3 x n
  // Node accelerations in frame axes minus the centrifugal part of the rigid motion.
  Eigen::Matrix<double, 6, 1> acc = ZR * wdot;
  Eigen::Matrix<double, 6, 3> d_acc_d_omega = Eigen::Matrix<double, 6, 3>::Zero();
  for (int a = 0; a < body.n_nodes_; ++a) {
    const Eigen::Vector3d r = body.X_[a] + q.segment<3>(6 * a);
    const Eigen::Vector3d centrifugal = omega * omega.dot(r) - omega.squaredNorm() * r;
    // d/d omega [omega (omega . r) - |omega|^2 r] = (omega . r) 1 + omega r^T - 2 r omega^T.
    const Eigen::Matrix3d d_centrifugal =
        omega.dot(r) * Eigen::Matrix3d::Identity() + omega * r.transpose() - 2.0 * r * omega.transpose();
    acc.noalias() -= kin.Z.middleCols<3>(6 * a) * centrifugal;
    d_acc_d_omega.noalias() -= kin.Z.middleCols<3>(6 * a) * d_centrifugal;
  }
  out.a.head<3>() = acc.head<3>() - frame.R.transpose() * gravity;
  out.a.segment<3>(3) = acc.tail<3>();
  out.a.tail<6>() << omega.x() * omega.x(), omega.y() * omega.y(), omega.z() * omega.z(), omega.x() * omega.y(),
      omega.x() * omega.z(), omega.y() * omega.z();
  out.d_wdot.topRows<6>() = ZR;
  Eigen::Matrix<double, 6, 3> d_products;
  d_products << 2 * omega.x(), 0, 0, 0, 2 * omega.y(), 0, 0, 0, 2 * omega.z(), omega.y(), omega.x(), 0, omega.z(), 0,
      omega.x(), 0, omega.z(), omega.y();
  out.d_w.topRows<6>().noalias() = d_acc_d_omega * d_omega;
  out.d_w.bottomRows<6>().noalias() = d_products * d_omega;
}

void StiffenedElasticForce(const SuperelementBody& body, BodyData& d, const BodyVelocity& w, const BodyVelocity& wdot,
                           const Eigen::Vector3d& g, InertiaLoadFactors& load, Eigen::VectorXd& f,
                           Eigen::MatrixXd* tangent) {
  if (body.has_inertia_stiffening()) {
    InertiaLoads(body, d, w, wdot, g, load);
    ElasticForce(body, d, &f, tangent, &load);
  } else {
    load.a.setZero();
    ElasticForce(body, d, &f, tangent);
  }
}

}  // namespace femb
