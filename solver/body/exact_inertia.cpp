// The exact inertia from the file's invariants: per-configuration products, force, mass,
// gyroscopic matrix, configuration tangent and the momentum source's local term.
#include "solver/body/exact_inertia.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "solver/body/body_blocks.h"
#include "solver/body/superelement_body.h"
#include "solver/rotation.h"

namespace femb {

using body_blocks::QuadraticDerivative;
using body_blocks::TurnBlocksInto;
using body_blocks::TurnColBlocks;
using body_blocks::TurnNodeBlocks;
using body_blocks::TurnRowBlocks;

void Exact(const SuperelementBody& body, const Eigen::VectorXd& q, const BodyKinematics& kin, ExactInertiaData& d) {
  const int n = body.n_coordinates();
  d.Y = kin.B;
  d.Y.noalias() += body.Phi_rig0_ * kin.Z;
  GammaColumns(body, q, d.H);
  // The stacked product Xi q (9 n) is the n x 9 matrix XQ column by column.
  d.XQ.resize(n, 9);
  Eigen::Map<Eigen::VectorXd>(d.XQ.data(), Eigen::Index(n) * 9).noalias() = body.Xi_stack_ * q;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) d.Xq(a, b) = q.dot(d.XQ.col(3 * a + b));
  d.has_products = false;
}

void GammaColumns(const SuperelementBody& body, const Eigen::VectorXd& v, Eigen::MatrixXd& out) {
  out.resize(body.n_coordinates(), 3);
  Eigen::Map<Eigen::VectorXd>(out.data(), Eigen::Index(body.n_coordinates()) * 3).noalias() = body.Gamma_stack_ * v;
}

const ExactInertiaData& ExactProducts(const SuperelementBody& body, BodyData& data) {
  ExactInertiaData& d = *data.exact;
  if (!d.has_products) {
    d.MY.noalias() = body.M_ * d.Y;
    d.HtY.noalias() = d.H.transpose() * d.Y;
    d.has_products = true;
  }
  return d;
}

void SubtractRateTerms(const SuperelementBody& body, const Eigen::VectorXd& q, const Eigen::Vector3d& Om,
                       const Eigen::VectorXd& Rw, const Eigen::VectorXd& qd, Eigen::VectorXd& r) {
  // c = Omega^ Rbar^T w + [Omega x udot_k; (d/dt J_l(theta_k)) thetadot_k] (header, "Exact inertia").
  for (int a = 0; a < 2 * body.n_nodes_; ++a) r.segment<3>(3 * a) -= Om.cross(Eigen::Vector3d(Rw.segment<3>(3 * a)));
  for (int k = 0; k < body.n_nodes_; ++k) {
    r.segment<3>(6 * k) -= Om.cross(Eigen::Vector3d(qd.segment<3>(6 * k)));
    r.segment<3>(6 * k + 3) -=
        LeftJacobianRate(Eigen::Vector3d(q.segment<3>(6 * k + 3)), Eigen::Vector3d(qd.segment<3>(6 * k + 3)));
  }
}

// Every temporary in data.exact_scratch (ExactScratch), each product into its own vector before
// the sums: no allocation once sized, and the same numbers as the expressions they replace.
void ExactInertiaForce(const SuperelementBody& body, BodyData& data, const BodyVelocity& w, const BodyVelocity& wdot,
                       Eigen::VectorXd& f, Eigen::VectorXd* f_acc) {
  const int blocks = 2 * body.n_nodes_;
  const ExactInertiaData& d = *data.exact;
  ExactScratch& s = data.exact_scratch;
  const Eigen::Matrix3d& R = data.frame.R;
  const Eigen::Matrix3d Rt = R.transpose();
  const Eigen::MatrixXd& Z = data.kin.Z;
  const Eigen::MatrixXd& B = data.kin.B;
  Eigen::VectorXd& Rw = s.Rw;
  TurnBlocksInto(Rt, w, blocks, Rw);
  Eigen::Matrix<double, 6, 1> xi;
  xi.noalias() = Z * Rw;
  const Eigen::Vector3d v = xi.head<3>(), Om = xi.tail<3>();
  Eigen::VectorXd& qd = s.qd;
  qd.noalias() = B * Rw;
  // r = Rbar^T wdot - c (header): xidot = Z r, qddot_loc = B r, ydot = Y r.
  Eigen::VectorXd& r = s.r;
  TurnBlocksInto(Rt, wdot, blocks, r);
  if (f_acc) ExactMassTimesTurned(body, data, r, *f_acc);
  SubtractRateTerms(body, data.q, Om, Rw, qd, r);
  Eigen::Vector3d Omd;
  Omd.noalias() = Z.bottomRows<3>() * r;
  Eigen::VectorXd &y = s.y, &yd = s.yd;
  y.noalias() = body.Phi_rig0_ * xi;
  y += qd;
  yd.noalias() = d.Y * r;
  Eigen::MatrixXd& Hd = s.Hd;
  GammaColumns(body, qd, Hd);
  Eigen::VectorXd &pi_q = s.pi_q, &pi_q_dot = s.pi_q_dot;
  pi_q.noalias() = body.M_ * y;
  s.t1.noalias() = d.H * Om;
  pi_q += s.t1;
  pi_q_dot.noalias() = body.M_ * yd;
  s.t1.noalias() = d.H * Omd;
  s.t2.noalias() = Hd * Om;
  pi_q_dot += s.t1;
  pi_q_dot += s.t2;
  Eigen::VectorXd& f_q = s.f_q;
  f_q = pi_q_dot;  // minus dT/dq below
  Eigen::Vector3d Hty, Htyd, Hdty;
  Hty.noalias() = d.H.transpose() * y;
  Htyd.noalias() = d.H.transpose() * yd;
  Hdty.noalias() = Hd.transpose() * y;
  Eigen::Vector3d h = Hty + d.Xq * Om, hd = Htyd + Hdty + d.Xq * Omd;
  for (int a = 0; a < 3; ++a) {
    s.t1.noalias() = body.Gamma_[size_t(a)].transpose() * y;
    f_q -= Om[a] * s.t1;
    for (int b = 0; b < 3; ++b) {
      f_q -= Om[a] * Om[b] * d.XQ.col(3 * a + b);
      hd[a] += Om[b] * qd.dot(d.XQ.col(3 * a + b) + d.XQ.col(3 * b + a));
    }
  }
  // pi_xi = Phi_rig0^T pi_q + [0; h]; f_xi = d/dt pi_xi + Kirchhoff's terms.
  Eigen::Matrix<double, 6, 1> pi_xi, f_xi;
  pi_xi.noalias() = body.Phi_rig0_.transpose() * pi_q;
  f_xi.noalias() = body.Phi_rig0_.transpose() * pi_q_dot;
  pi_xi.tail<3>() += h;
  f_xi.tail<3>() += hd;
  const Eigen::Vector3d pi_v = pi_xi.head<3>(), pi_w = pi_xi.tail<3>();
  f_xi.head<3>() += Om.cross(pi_v);
  f_xi.tail<3>() += Om.cross(pi_w) + v.cross(pi_v);
  f.noalias() = Z.transpose() * f_xi;
  s.t1.noalias() = B.transpose() * f_q;
  f += s.t1;
  TurnBlocksInto(R, f, blocks, f);
}

// The force at w = 0 for the acceleration Rbar r (r = Rbar^T wdot; xi = qd = y = 0): M_g wdot,
// in O(n^2) (s.y, s.pi_q_dot and s.t1 are overwritten).
void ExactMassTimesTurned(const SuperelementBody& body, BodyData& data, const Eigen::VectorXd& r,
                          Eigen::VectorXd& out) {
  const ExactInertiaData& d = *data.exact;
  ExactScratch& s = data.exact_scratch;
  const Eigen::MatrixXd& Z = data.kin.Z;
  const Eigen::MatrixXd& B = data.kin.B;
  Eigen::Vector3d Omd0;
  Omd0.noalias() = Z.bottomRows<3>() * r;
  Eigen::VectorXd& yd0 = s.y;
  yd0.noalias() = d.Y * r;
  Eigen::VectorXd& pi_q_dot0 = s.pi_q_dot;
  pi_q_dot0.noalias() = body.M_ * yd0;
  s.t1.noalias() = d.H * Omd0;
  pi_q_dot0 += s.t1;
  Eigen::Matrix<double, 6, 1> f_xi0;
  f_xi0.noalias() = body.Phi_rig0_.transpose() * pi_q_dot0;
  Eigen::Vector3d Hty0;
  Hty0.noalias() = d.H.transpose() * yd0;
  f_xi0.tail<3>() += Hty0 + d.Xq * Omd0;
  out.noalias() = Z.transpose() * f_xi0;
  s.t1.noalias() = B.transpose() * pi_q_dot0;
  out += s.t1;
  TurnBlocksInto(data.frame.R, out, 2 * body.n_nodes_, out);
}

void ExactMomentumSource(const SuperelementBody& body, BodyData& data, const BodyVelocity& w, Eigen::VectorXd& out) {
  // T(q, w) = T_hat(q_loc, Rbar^T w) (T is invariant under rigid motions), so at fixed w
  // dT/dq = G^T p (the frame's turning, as for the corotational inertia) + Rbar B^T g with
  // g = dT_hat/dq_loc at fixed w_hat = Rbar^T w. T_hat = T_L(xi(q_loc), q_loc, qdot(q_loc)) with
  // xi = Z w_hat, qdot = B w_hat (header, "Exact inertia"): w_hat = Phi_rig(q) xi + D^-1(q) qdot
  // with Phi_CB qdot = 0, differentiated at fixed w_hat, gives delta xi = -Z a, delta qdot = -B a,
  // a = (d Phi_rig) xi + (d D^-1) qdot, so
  //   g = dT_L/dq|explicit - (a's coefficients of p_hat),  p_hat = Z^T pi_xi + B^T pi_q = Rbar^T p:
  //   dT_L/dq|explicit = sum_a Omega_a Gamma_a^T y + sum_ab Omega_a Omega_b Xi_ab q,
  //   node k's translation rows: a = Omega x delta u_k        -> p_hat_t,k x Omega,
  //   node k's rotation rows:    a = (dJ_l(theta_k)) thetadot -> d/dtheta [p_hat_r,k^T J_l thetadot_k].
  const int blocks = 2 * body.n_nodes_;
  const ExactInertiaData& d = *data.exact;
  ExactScratch& s = data.exact_scratch;
  const Eigen::MatrixXd& Z = data.kin.Z;
  const Eigen::MatrixXd& B = data.kin.B;
  Eigen::VectorXd& Rw = s.Rw;
  TurnBlocksInto(data.frame.R.transpose(), w, blocks, Rw);
  Eigen::Matrix<double, 6, 1> xi;
  xi.noalias() = Z * Rw;
  const Eigen::Vector3d Om = xi.tail<3>();
  Eigen::VectorXd &qd = s.qd, &y = s.y, &pi_q = s.pi_q;
  qd.noalias() = B * Rw;
  y.noalias() = body.Phi_rig0_ * xi;
  y += qd;
  pi_q.noalias() = body.M_ * y;
  s.t1.noalias() = d.H * Om;
  pi_q += s.t1;
  Eigen::Matrix<double, 6, 1> pi_xi;
  pi_xi.noalias() = body.Phi_rig0_.transpose() * pi_q;
  Eigen::Vector3d Hty;
  Hty.noalias() = d.H.transpose() * y;
  pi_xi.tail<3>() += Hty + d.Xq * Om;
  Eigen::VectorXd &p_hat = s.p_hat, &g = s.g;
  p_hat.noalias() = Z.transpose() * pi_xi;
  s.t1.noalias() = B.transpose() * pi_q;
  p_hat += s.t1;
  g.setZero(body.n_coordinates());
  for (int a = 0; a < 3; ++a) {
    s.t1.noalias() = body.Gamma_[size_t(a)].transpose() * y;
    g += Om[a] * s.t1;
    for (int b = 0; b < 3; ++b) g += Om[a] * Om[b] * d.XQ.col(3 * a + b);
  }
  for (int k = 0; k < body.n_nodes_; ++k) {
    g.segment<3>(6 * k) -= Eigen::Vector3d(p_hat.segment<3>(6 * k)).cross(Om);
    // d/dtheta [p^T J_l(theta) v] = -(d/dtheta [J_l^-1(theta)^T J_l^T p])^T J_l v (d J_l =
    // -J_l d(J_l^-1) J_l), with J_l^T p and J_l v held.
    const Eigen::Matrix3d J = data.kin.Jinv[size_t(k)].inverse();
    const Eigen::Vector3d theta = data.q.segment<3>(6 * k + 3);
    const Eigen::Vector3d Jtp = J.transpose() * Eigen::Vector3d(p_hat.segment<3>(6 * k + 3));
    const Eigen::Vector3d Jv = J * Eigen::Vector3d(qd.segment<3>(6 * k + 3));
    g.segment<3>(6 * k + 3) += LeftJacobianInverseTransposeDerivative(theta, Jtp).transpose() * Jv;
  }
  out.noalias() = B.transpose() * g;
  TurnBlocksInto(data.frame.R, out, blocks, out);
}

namespace {

// ExactGyroscopic's stages. They are inlined into it: the compiler then sees the same statements
// in the same order as in one function, and contracts the same products into fused
// multiply-adds (-march=native), so the matrix is the same to the bit.

// The frame's motion xi = (v, Omega) and Omega~ of ExactGyroscopic.
struct GyroscopicMotion {
  Eigen::Matrix<double, 6, 1> xi;
  Eigen::Vector3d v, Om;
  Eigen::Matrix3d Om_x;
};

// The kinematic quantities of the force and their w-derivatives: Rbar^T w, xi (dxi = Z Rbar^T),
// qdot_loc (dqd = B Rbar^T), dr = -dc, dOmegadot = Z_r dr, y = Phi_rig0 xi + qdot_loc and dy.
[[gnu::always_inline]] inline void GyroscopicKinematics(const SuperelementBody& body, BodyData& data,
                                                        const BodyVelocity& w, GyroscopicMotion& m) {
  const int n = body.n_coordinates(), blocks = 2 * body.n_nodes_;
  ExactScratch& s = data.exact_scratch;
  const Eigen::MatrixXd& Z = data.kin.Z;
  const Eigen::MatrixXd& B = data.kin.B;
  const Eigen::Matrix3d Rt = data.frame.R.transpose();
  Eigen::VectorXd& Rw = s.Rw;
  TurnBlocksInto(Rt, w, blocks, Rw);
  m.xi.noalias() = Z * Rw;
  m.v = m.xi.head<3>();
  m.Om = m.xi.tail<3>();
  Eigen::MatrixXd& dxi = s.dxi;  // Z Rbar^T
  dxi = Z;
  TurnColBlocks(dxi, blocks, [&](int) { return Rt; });
  Eigen::MatrixXd &dv = s.dv, &dOm = s.dOm;
  dv = dxi.topRows<3>();
  dOm = dxi.bottomRows<3>();
  Eigen::VectorXd& qd = s.qd;
  qd.noalias() = B * Rw;
  Eigen::MatrixXd& dqd = s.dqd;  // B Rbar^T
  dqd = B;
  TurnColBlocks(dqd, blocks, [&](int) { return Rt; });
  // r = Rbar^T wdot - c(w): dr = -dc. d(Rbar^T w) = Rbar^T: block a is R^T at column block a.
  Eigen::MatrixXd& dr = s.dr;
  dr.setZero(n, n);
  m.Om_x = Skew<double>(m.Om);
  const Eigen::Matrix3d& Om_x = m.Om_x;
  Eigen::MatrixXd &t3 = s.t3, &t4 = s.t4;
  for (int a = 0; a < blocks; ++a) {
    dr.middleRows<3>(3 * a).noalias() += Skew<double>(Eigen::Vector3d(Rw.segment<3>(3 * a))) * dOm;
    dr.block<3, 3>(3 * a, 3 * a) -= Om_x * Rt;
  }
  for (int k = 0; k < body.n_nodes_; ++k) {
    const Eigen::Matrix3d minus_qd_x = -Skew<double>(Eigen::Vector3d(qd.segment<3>(6 * k)));
    t3.noalias() = minus_qd_x * dOm;
    t4.noalias() = Om_x * dqd.middleRows<3>(6 * k);
    dr.middleRows<3>(6 * k) -= t3 + t4;
    // LeftJacobianRate is quadratic in thetadot: its derivative by polarization, exactly.
    const Eigen::Vector3d theta = data.q.segment<3>(6 * k + 3), thetadot = qd.segment<3>(6 * k + 3);
    const Eigen::Matrix3d DL =
        QuadraticDerivative(thetadot, [&](const Eigen::Vector3d& e) { return LeftJacobianRate(theta, e); });
    t3.noalias() = DL * dqd.middleRows<3>(6 * k + 3);
    dr.middleRows<3>(6 * k + 3) -= t3;
  }
  s.dOmd.noalias() = Z.bottomRows<3>() * dr;
  Eigen::VectorXd& y = s.y;
  y.noalias() = body.Phi_rig0_ * m.xi;
  y += qd;
  Eigen::MatrixXd& dy = s.dy;
  dy.noalias() = body.Phi_rig0_ * dxi;
  dy += dqd;
}

// The local coordinates' force f_q's derivative df_q, up to its Xi terms (the Gamma terms with
// M dyd and H^T dyd, dyd = Y dr, from M Y and H^T Y kept per configuration), and what the frame's
// force needs of it: Gamma(Omega), Gamma_a qd, Gamma_a^T y, pi_q and `base`.
[[gnu::always_inline]] inline void GyroscopicLocalForce(const SuperelementBody& body, const ExactInertiaData& d,
                                                        ExactScratch& s, const GyroscopicMotion& m) {
  const int n = body.n_coordinates();
  // Gamma(Om) = sum_a Om_a Gamma_a: the three Gamma_a dqd and Gamma_a^T dy products in one each;
  // the rows y^T Gamma_a dqd as (Gamma_a^T y)^T dqd.
  Eigen::MatrixXd& G_Om = s.G_Om;
  G_Om = m.Om[0] * body.Gamma_[0];
  for (int a = 1; a < 3; ++a) G_Om += m.Om[a] * body.Gamma_[size_t(a)];
  GammaColumns(body, s.qd, s.Hd);  // Gamma_a qd
  Eigen::MatrixXd& Gty = s.Gty;    // Gamma_a^T y
  Gty.resize(n, 3);
  for (int a = 0; a < 3; ++a) Gty.col(a).noalias() = body.Gamma_[size_t(a)].transpose() * s.y;
  Eigen::VectorXd& pi_q = s.pi_q;
  pi_q.noalias() = body.M_ * s.y;
  s.t1.noalias() = d.H * m.Om;
  pi_q += s.t1;
  // d pi_qdot = base + G_Om dqd and df_q = d pi_qdot - G_Om^T dy - Gty dOm with
  // dy = Phi_rig0 dxi + dqd: the two n x n products with G_Om as one, (G_Om - G_Om^T) dqd.
  Eigen::MatrixXd& base = s.base;
  base.noalias() = d.MY * s.dr;
  base.noalias() += d.H * s.dOmd;
  base.noalias() += s.Hd * s.dOm;
  Eigen::MatrixXd& df_q = s.df_q;
  df_q = base;
  Eigen::MatrixXd& G_skew = s.G_skew;
  G_skew = G_Om - G_Om.transpose();
  df_q.noalias() += G_skew * s.dqd;
  Eigen::MatrixXd& GtP = s.GtP;  // n x 6
  GtP.noalias() = G_Om.transpose() * body.Phi_rig0_;
  df_q.noalias() -= GtP * s.dxi;
  df_q.noalias() -= Gty * s.dOm;
}

// The frame's force f_xi's derivative df_xi (Kirchhoff's equations: d/dt dT/dxi and the
// Omega x terms), with the Xi terms of df_q and of the angular momentum's rate.
[[gnu::always_inline]] inline void GyroscopicFrameForce(const SuperelementBody& body, const ExactInertiaData& d,
                                                        ExactScratch& s, const GyroscopicMotion& m) {
  const Eigen::Vector3d& Om = m.Om;
  const Eigen::MatrixXd &dOm = s.dOm, &dqd = s.dqd, &dy = s.dy;
  Eigen::MatrixXd &t3 = s.t3, &t4 = s.t4, &t5 = s.t5, &t6 = s.t6;
  Eigen::Vector3d Hty;
  Hty.noalias() = d.H.transpose() * s.y;
  const Eigen::Vector3d h = Hty + d.Xq * Om;
  Eigen::MatrixXd& dh = s.dh;
  t3.noalias() = d.H.transpose() * dy;
  t4.noalias() = d.Xq * dOm;
  dh = t3 + t4;
  Eigen::MatrixXd& dhd = s.dhd;
  dhd.noalias() = d.HtY * s.dr;
  t3.noalias() = d.Xq * s.dOmd;
  t4.noalias() = s.Gty.transpose() * dqd;
  t5.noalias() = s.Hd.transpose() * dy;
  dhd += t3;
  dhd += t4;
  dhd += t5;
  Eigen::RowVectorXd &row = s.row, &row2 = s.row2;
  Eigen::VectorXd& S_ab = s.S_ab;
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) {
      const auto XQab = d.XQ.col(3 * a + b);
      row = Om[b] * dOm.row(a) + Om[a] * dOm.row(b);
      s.df_q.noalias() -= XQab * row;
      S_ab = XQab + d.XQ.col(3 * b + a);
      row2.noalias() = S_ab.transpose() * dqd;
      dhd.row(a) += s.qd.dot(S_ab) * dOm.row(b) + Om[b] * row2;
    }
  }
  Eigen::Matrix<double, 6, 1> pi_xi;
  pi_xi.noalias() = body.Phi_rig0_.transpose() * s.pi_q;
  pi_xi.tail<3>() += h;
  const Eigen::Vector3d pi_v = pi_xi.head<3>(), pi_w = pi_xi.tail<3>();
  // d pi_q = M dy + H dOm enters only through Phi_rig0^T: 6 rows.
  Eigen::MatrixXd& dpi_xi = s.dpi_xi;
  dpi_xi.noalias() = body.PtM_ * dy;
  s.PH.noalias() = body.Phi_rig0_.transpose() * d.H;
  s.t8.noalias() = s.PH * dOm;  // 6 x n
  dpi_xi += s.t8;
  dpi_xi.bottomRows<3>() += dh;
  Eigen::MatrixXd& df_xi = s.df_xi;
  df_xi.noalias() = body.Phi_rig0_.transpose() * s.base;
  s.PG.noalias() = body.Phi_rig0_.transpose() * s.G_Om;
  df_xi.noalias() += s.PG * dqd;
  df_xi.bottomRows<3>() += dhd;
  Eigen::MatrixXd &dpi_v = s.dpi_v, &dpi_w = s.dpi_w;
  dpi_v = dpi_xi.topRows<3>();
  dpi_w = dpi_xi.bottomRows<3>();
  const Eigen::Matrix3d minus_pi_v_x = -Skew<double>(pi_v), minus_pi_w_x = -Skew<double>(pi_w);
  t3.noalias() = minus_pi_v_x * dOm;
  t4.noalias() = m.Om_x * dpi_v;
  df_xi.topRows<3>() += t3 + t4;
  t3.noalias() = minus_pi_w_x * dOm;
  t4.noalias() = m.Om_x * dpi_w;
  t5.noalias() = Skew<double>(pi_v) * s.dv;
  t6.noalias() = Skew<double>(m.v) * dpi_v;
  df_xi.bottomRows<3>() += t3 + t4 - t5 + t6;
}

}  // namespace

void ExactGyroscopic(const SuperelementBody& body, BodyData& data, const BodyVelocity& w, Eigen::MatrixXd& G) {
  // ExactInertiaForce is A(q) wdot + g(q, w), g quadratic in w with no wdot: its derivative by
  // w is that of g. Forward mode by hand: every quantity of the force that depends on w carries
  // its n columns d/dw (prefix d), in the order of ExactInertiaForce. The temporaries are
  // data.exact_scratch's, each product into its own before the sums (as ExactInertiaForce).
  const ExactInertiaData& d = ExactProducts(body, data);
  ExactScratch& s = data.exact_scratch;
  GyroscopicMotion m;
  GyroscopicKinematics(body, data, w, m);
  GyroscopicLocalForce(body, d, s, m);
  GyroscopicFrameForce(body, d, s, m);
  // G = Rbar (Z^T df_xi + B^T df_q).
  G.noalias() = data.kin.Z.transpose() * s.df_xi;
  s.t7.noalias() = data.kin.B.transpose() * s.df_q;
  G += s.t7;
  TurnRowBlocks(G, 2 * body.n_nodes_, [&](int) { return data.frame.R; });
}

const Eigen::MatrixXd& ExactMass(const SuperelementBody& body, BodyData& data) {
  if (data.has_exact_mass) return data.exact_mass;
  const ExactInertiaData& d = ExactProducts(body, data);
  const Eigen::Matrix3d& R = data.frame.R;
  const auto Zr = data.kin.Z.bottomRows<3>();
  BodyScratch& s = data.scratch;
  s.n3a.noalias() = d.Y.transpose() * d.H;  // n x 3
  Eigen::MatrixXd& YHZ = s.nn1;             // (Y^T H) Zr
  YHZ.noalias() = s.n3a * Zr;
  s.n3b.noalias() = Zr.transpose() * d.Xq;  // n x 3
  Eigen::MatrixXd& Mg = data.exact_mass;
  Mg.noalias() = d.Y.transpose() * d.MY;
  Mg += YHZ;
  Mg += YHZ.transpose();
  Mg.noalias() += s.n3b * Zr;
  // Rbar Mbar Rbar^T block by block.
  body_blocks::TurnNodeBlocks(Mg, 2 * body.n_nodes_, R);
  data.has_exact_mass = true;
  return Mg;
}

Eigen::MatrixXd ExactInertiaConfigurationTangent(const SuperelementBody& body, BodyData& d, const BodyVelocity& w,
                                                 const BodyVelocity& wdot) {
  // Central differences of the whole force at fixed (w, wdot), the frame re-solved.
  const int n = body.n_coordinates();
  const Eigen::VectorXd& w_used = w;
  Eigen::MatrixXd tangent(n, n);
  Eigen::VectorXd f_plus, f_minus;
  for (int i = 0; i < n; ++i) {
    double step = 0.0;
    const BodyConfiguration plus = Perturbed(body, d.c, i, 1.0, &step), minus = Perturbed(body, d.c, i, -1.0, &step);
    BodyData at_plus = Evaluate(body, plus, SolveFrame(body, plus, d.frame));
    ExactInertiaForce(body, at_plus, w_used, wdot, f_plus, nullptr);
    BodyData at_minus = Evaluate(body, minus, SolveFrame(body, minus, d.frame));
    ExactInertiaForce(body, at_minus, w_used, wdot, f_minus, nullptr);
    tangent.col(i) = (f_plus - f_minus) / (2 * step);
  }
  return tangent;
}

}  // namespace femb
