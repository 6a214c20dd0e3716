// The exact inertia of the reduced field in the floating frame (superelement_body.h, "Exact
// inertia"): per-configuration products, force, mass matrix, gyroscopic matrix and the
// configuration tangent by central differences.
#include <Eigen/Dense>

#include "solver/body/body_blocks.h"
#include "solver/body/superelement_body.h"
#include "solver/rotation.h"

namespace femb {

using body_blocks::QuadraticDerivative;
using body_blocks::TurnBlocks;
using body_blocks::TurnColBlocks;
using body_blocks::TurnRowBlocks;

SuperelementBody::ExactData SuperelementBody::Exact(const Eigen::VectorXd& q, const Kinematics& kin) const {
  const int n = n_coordinates();
  ExactData d;
  d.Y = kin.B;
  d.Y.noalias() += Phi_rig0_ * kin.Z;
  const Eigen::VectorXd xq = Xi_stack_ * q;
  d.H = GammaColumns(q);
  d.XQ = Eigen::Map<const Eigen::MatrixXd>(xq.data(), n, 9);
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) d.Xq(a, b) = q.dot(d.XQ.col(3 * a + b));
  return d;
}

Eigen::MatrixXd SuperelementBody::GammaColumns(const Eigen::VectorXd& v) const {
  const Eigen::VectorXd stacked = Gamma_stack_ * v;
  return Eigen::Map<const Eigen::MatrixXd>(stacked.data(), n_coordinates(), 3);
}

const SuperelementBody::ExactData& SuperelementBody::ExactProducts(const Data& data) const {
  const ExactData& d = *data.exact;
  if (d.MY.size() == 0) {
    d.MY.noalias() = M_ * d.Y;
    d.HtY.noalias() = d.H.transpose() * d.Y;
  }
  return d;
}

Eigen::VectorXd SuperelementBody::ExactInertiaForce(const Data& data, const BodyVelocity& w,
                                                    const BodyVelocity& wdot, Eigen::VectorXd* f_acc) const {
  const int blocks = 2 * n_nodes_;
  const ExactData& d = *data.exact;
  const Eigen::Matrix3d& R = data.frame.R;
  const Eigen::MatrixXd& Z = data.kin.Z;
  const Eigen::MatrixXd& B = data.kin.B;
  const Eigen::VectorXd Rw = TurnBlocks(R.transpose(), w, blocks);
  const Eigen::Matrix<double, 6, 1> xi = Z * Rw;
  const Eigen::Vector3d v = xi.head<3>(), Om = xi.tail<3>();
  const Eigen::VectorXd qd = B * Rw;
  // r = Rbar^T wdot - c (header): xidot = Z r, qddot_loc = B r, ydot = Y r.
  Eigen::VectorXd r = TurnBlocks(R.transpose(), wdot, blocks);
  if (f_acc) {
    // The same force at w = 0: r = Rbar^T wdot, xi = qd = y = 0.
    const Eigen::Vector3d Omd0 = Z.bottomRows<3>() * r;
    const Eigen::VectorXd yd0 = d.Y * r;
    const Eigen::VectorXd pi_q_dot0 = M_ * yd0 + d.H * Omd0;
    Eigen::Matrix<double, 6, 1> f_xi0 = Phi_rig0_.transpose() * pi_q_dot0;
    f_xi0.tail<3>() += d.H.transpose() * yd0 + d.Xq * Omd0;
    *f_acc = TurnBlocks(R, Eigen::VectorXd(Z.transpose() * f_xi0 + B.transpose() * pi_q_dot0), blocks);
  }
  for (int a = 0; a < blocks; ++a) r.segment<3>(3 * a) -= Om.cross(Eigen::Vector3d(Rw.segment<3>(3 * a)));
  for (int k = 0; k < n_nodes_; ++k) {
    r.segment<3>(6 * k) -= Om.cross(Eigen::Vector3d(qd.segment<3>(6 * k)));
    r.segment<3>(6 * k + 3) -=
        LeftJacobianRate(Eigen::Vector3d(data.q.segment<3>(6 * k + 3)), Eigen::Vector3d(qd.segment<3>(6 * k + 3)));
  }
  const Eigen::Vector3d Omd = Z.bottomRows<3>() * r;
  const Eigen::VectorXd y = Phi_rig0_ * xi + qd, yd = d.Y * r;
  const Eigen::MatrixXd Hd = GammaColumns(qd);
  const Eigen::VectorXd pi_q = M_ * y + d.H * Om;
  const Eigen::VectorXd pi_q_dot = M_ * yd + d.H * Omd + Hd * Om;
  Eigen::VectorXd f_q = pi_q_dot;  // minus dT/dq below
  Eigen::Vector3d h = d.H.transpose() * y + d.Xq * Om, hd = d.H.transpose() * yd + Hd.transpose() * y + d.Xq * Omd;
  for (int a = 0; a < 3; ++a) {
    f_q -= Om[a] * (Gamma_[size_t(a)].transpose() * y);
    for (int b = 0; b < 3; ++b) {
      f_q -= Om[a] * Om[b] * d.XQ.col(3 * a + b);
      hd[a] += Om[b] * qd.dot(d.XQ.col(3 * a + b) + d.XQ.col(3 * b + a));
    }
  }
  // pi_xi = Phi_rig0^T pi_q + [0; h]; f_xi = d/dt pi_xi + Kirchhoff's terms.
  Eigen::Matrix<double, 6, 1> pi_xi = Phi_rig0_.transpose() * pi_q;
  Eigen::Matrix<double, 6, 1> f_xi = Phi_rig0_.transpose() * pi_q_dot;
  pi_xi.tail<3>() += h;
  f_xi.tail<3>() += hd;
  const Eigen::Vector3d pi_v = pi_xi.head<3>(), pi_w = pi_xi.tail<3>();
  f_xi.head<3>() += Om.cross(pi_v);
  f_xi.tail<3>() += Om.cross(pi_w) + v.cross(pi_v);
  return TurnBlocks(R, Eigen::VectorXd(Z.transpose() * f_xi + B.transpose() * f_q), blocks);
}

Eigen::MatrixXd SuperelementBody::ExactGyroscopic(const Data& data, const BodyVelocity& w) const {
  // ExactInertiaForce is A(q) wdot + g(q, w), g quadratic in w with no wdot: its derivative by
  // w is that of g. Forward mode by hand: every quantity of the force that depends on w carries
  // its n columns d/dw (prefix d), in the order of ExactInertiaForce.
  const int n = n_coordinates(), blocks = 2 * n_nodes_;
  const ExactData& d = ExactProducts(data);
  const Eigen::Matrix3d& R = data.frame.R;
  const Eigen::MatrixXd& Z = data.kin.Z;
  const Eigen::MatrixXd& B = data.kin.B;
  const Eigen::Matrix3d Rt = R.transpose();
  const auto times_Rbar_t = [&](Eigen::MatrixXd X) {  // X Rbar^T
    TurnColBlocks(X, blocks, [&](int) { return Rt; });
    return X;
  };
  const Eigen::VectorXd Rw = TurnBlocks(R.transpose(), w, blocks);
  const Eigen::Matrix<double, 6, 1> xi = Z * Rw;
  const Eigen::Vector3d v = xi.head<3>(), Om = xi.tail<3>();
  const Eigen::MatrixXd dxi = times_Rbar_t(Z);
  const Eigen::MatrixXd dv = dxi.topRows<3>(), dOm = dxi.bottomRows<3>();
  const Eigen::VectorXd qd = B * Rw;
  const Eigen::MatrixXd dqd = times_Rbar_t(B);
  // r = Rbar^T wdot - c(w): dr = -dc. d(Rbar^T w) = Rbar^T: block a is R^T at column block a.
  Eigen::MatrixXd dr = Eigen::MatrixXd::Zero(n, n);
  const Eigen::Matrix3d Om_x = Skew<double>(Om);
  for (int a = 0; a < blocks; ++a) {
    dr.middleRows<3>(3 * a).noalias() += Skew<double>(Eigen::Vector3d(Rw.segment<3>(3 * a))) * dOm;
    dr.block<3, 3>(3 * a, 3 * a) -= Om_x * Rt;
  }
  for (int k = 0; k < n_nodes_; ++k) {
    dr.middleRows<3>(6 * k) -= -Skew<double>(Eigen::Vector3d(qd.segment<3>(6 * k))) * dOm + Om_x * dqd.middleRows<3>(6 * k);
    // LeftJacobianRate is quadratic in thetadot: its derivative by polarization, exactly.
    const Eigen::Vector3d theta = data.q.segment<3>(6 * k + 3), thetadot = qd.segment<3>(6 * k + 3);
    const Eigen::Matrix3d DL =
        QuadraticDerivative(thetadot, [&](const Eigen::Vector3d& e) { return LeftJacobianRate(theta, e); });
    dr.middleRows<3>(6 * k + 3) -= DL * dqd.middleRows<3>(6 * k + 3);
  }
  const Eigen::MatrixXd dOmd = Z.bottomRows<3>() * dr;
  const Eigen::VectorXd y = Phi_rig0_ * xi + qd;
  const Eigen::MatrixXd dy = Phi_rig0_ * dxi + dqd;
  // Gamma(Om) = sum_a Om_a Gamma_a: the three Gamma_a dqd and Gamma_a^T dy products in one each;
  // the rows y^T Gamma_a dqd as (Gamma_a^T y)^T dqd.
  Eigen::MatrixXd G_Om = Om[0] * Gamma_[0];
  for (int a = 1; a < 3; ++a) G_Om += Om[a] * Gamma_[size_t(a)];
  const Eigen::MatrixXd Hd = GammaColumns(qd);  // Gamma_a qd
  Eigen::MatrixXd Gty(n, 3);                     // Gamma_a^T y
  for (int a = 0; a < 3; ++a) Gty.col(a).noalias() = Gamma_[size_t(a)].transpose() * y;
  const Eigen::VectorXd pi_q = M_ * y + d.H * Om;
  // M dyd and H^T dyd with dyd = Y dr: (M Y) dr and (H^T Y) dr, M Y and H^T Y kept per configuration.
  // d pi_qdot = base + G_Om dqd and df_q = d pi_qdot - G_Om^T dy - Gty dOm with
  // dy = Phi_rig0 dxi + dqd: the two n x n products with G_Om as one, (G_Om - G_Om^T) dqd.
  Eigen::MatrixXd base = d.MY * dr;
  base.noalias() += d.H * dOmd;
  base.noalias() += Hd * dOm;
  Eigen::MatrixXd df_q = base;
  {
    const Eigen::MatrixXd G_skew = G_Om - G_Om.transpose();
    df_q.noalias() += G_skew * dqd;
    const Eigen::MatrixXd GtP = G_Om.transpose() * Phi_rig0_;  // n x 6
    df_q.noalias() -= GtP * dxi;
    df_q.noalias() -= Gty * dOm;
  }
  const Eigen::Vector3d h = d.H.transpose() * y + d.Xq * Om;
  const Eigen::MatrixXd dh = d.H.transpose() * dy + d.Xq * dOm;
  Eigen::MatrixXd dhd = d.HtY * dr + d.Xq * dOmd + Gty.transpose() * dqd + Hd.transpose() * dy;
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) {
      const auto XQab = d.XQ.col(3 * a + b);
      df_q -= XQab * (Om[b] * dOm.row(a) + Om[a] * dOm.row(b));
      const Eigen::VectorXd S_ab = XQab + d.XQ.col(3 * b + a);
      dhd.row(a) += qd.dot(S_ab) * dOm.row(b) + Om[b] * (S_ab.transpose() * dqd);
    }
  }
  Eigen::Matrix<double, 6, 1> pi_xi = Phi_rig0_.transpose() * pi_q;
  pi_xi.tail<3>() += h;
  const Eigen::Vector3d pi_v = pi_xi.head<3>(), pi_w = pi_xi.tail<3>();
  // d pi_q = M dy + H dOm enters only through Phi_rig0^T: 6 rows.
  Eigen::MatrixXd dpi_xi = PtM_ * dy + (Phi_rig0_.transpose() * d.H) * dOm;
  dpi_xi.bottomRows<3>() += dh;
  Eigen::MatrixXd df_xi = Phi_rig0_.transpose() * base;
  df_xi.noalias() += (Phi_rig0_.transpose() * G_Om) * dqd;
  df_xi.bottomRows<3>() += dhd;
  const Eigen::MatrixXd dpi_v = dpi_xi.topRows<3>(), dpi_w = dpi_xi.bottomRows<3>();
  df_xi.topRows<3>() += -Skew<double>(pi_v) * dOm + Om_x * dpi_v;
  df_xi.bottomRows<3>() += -Skew<double>(pi_w) * dOm + Om_x * dpi_w - Skew<double>(pi_v) * dv + Skew<double>(v) * dpi_v;
  Eigen::MatrixXd G = Z.transpose() * df_xi + B.transpose() * df_q;
  TurnRowBlocks(G, blocks, [&](int) { return R; });
  return G;
}

const Eigen::MatrixXd& SuperelementBody::ExactMass(const Data& data) const {
  if (data.exact_mass) return *data.exact_mass;
  const ExactData& d = ExactProducts(data);
  const Eigen::Matrix3d& R = data.frame.R;
  const Eigen::MatrixXd Zr = data.kin.Z.bottomRows<3>();
  const Eigen::MatrixXd YHZ = d.Y.transpose() * d.H * Zr;
  Eigen::MatrixXd Mg = d.Y.transpose() * d.MY + YHZ + YHZ.transpose() + Zr.transpose() * d.Xq * Zr;
  // Rbar Mbar Rbar^T block by block.
  const Eigen::Matrix3d Rt = R.transpose();
  TurnRowBlocks(Mg, 2 * n_nodes_, [&](int) { return R; });
  TurnColBlocks(Mg, 2 * n_nodes_, [&](int) { return Rt; });
  data.exact_mass = std::move(Mg);
  return *data.exact_mass;
}

Eigen::MatrixXd SuperelementBody::ExactInertiaConfigurationTangent(const Data& d, const BodyVelocity& w,
                                                                   const BodyVelocity& wdot) const {
  // Central differences of the whole force at fixed (w, wdot), the frame re-solved.
  const int n = n_coordinates();
  const Eigen::VectorXd& w_used = w;
  Eigen::MatrixXd tangent(n, n);
  for (int i = 0; i < n; ++i) {
    double step = 0.0;
    const BodyConfiguration plus = Perturbed(d.c, i, 1.0, &step), minus = Perturbed(d.c, i, -1.0, &step);
    const Eigen::VectorXd f_plus = ExactInertiaForce(Evaluate(plus, SolveFrame(plus, d.frame)), w_used, wdot);
    const Eigen::VectorXd f_minus = ExactInertiaForce(Evaluate(minus, SolveFrame(minus, d.frame)), w_used, wdot);
    tangent.col(i) = (f_plus - f_minus) / (2 * step);
  }
  return tangent;
}

}  // namespace femb
