// The corotational inertia of a superelement (thesis 3.22, 4.9; superelement_body.h "Inertia
// force from the corotational kinetic energy"): the velocity maps P and U, M_g = P^T M P, the
// quadratic velocity terms and their derivative, the generalized momentum and its configuration
// derivative, and the momentum source terms of the midpoint scheme.
#include <Eigen/Dense>

#include "solver/body/body_blocks.h"
#include "solver/body/superelement_body.h"
#include "solver/rotation.h"

namespace femb {

using body_blocks::TurnColBlocks;
using body_blocks::TurnRowBlocks;

const BodyVelocityMaps& SuperelementBody::MapsOf(Data& d) const {
  if (!d.has_maps) {
    BodyVelocityMaps& maps = d.maps;
    VelocityMaps(d, &maps.P, &maps.U);
    // M_g = P^T M P with P block diagonal (3 x 3 blocks, then 1 on the modal rows).
    maps.Mg = M_;
    TurnRowBlocks(maps.Mg, 2 * n_nodes_,
                  [&](int a) { return Eigen::Matrix3d(maps.P.block<3, 3>(3 * a, 3 * a).transpose()); });
    TurnColBlocks(maps.Mg, 2 * n_nodes_, [&](int a) { return Eigen::Matrix3d(maps.P.block<3, 3>(3 * a, 3 * a)); });
    d.has_maps = true;
  }
  return d.maps;
}

void SuperelementBody::VelocityMaps(Data& d, Eigen::MatrixXd* P, Eigen::MatrixXd* U) const {
  const int n = n_coordinates();
  const BodyConfiguration& c = d.c;
  const FrameSolution& frame = d.frame;
  const Kinematics& kin = d.kin;
  P->setIdentity(n, n);
  for (int a = 0; a < n_nodes_; ++a) {
    P->block<3, 3>(6 * a, 6 * a) = frame.R.transpose();
    P->block<3, 3>(6 * a + 3, 6 * a + 3) = options_.cardona_option_b ? c.R[a].transpose() : frame.R.transpose();
  }
  // Spatial variation of the frame rotation: d pi_j = R_j (Z Rbar^T dq)_rot (thesis 3.17).
  Eigen::MatrixXd& Zr = d.scratch.n3a;
  Zr = kin.Z.bottomRows<3>();
  const Eigen::Matrix3d Rt = frame.R.transpose();
  TurnColBlocks(Zr, 2 * n_nodes_, [&](int) { return Rt; });
  U->resize(3, n);
  U->noalias() = frame.R * Zr;
}

void SuperelementBody::VelocityMapRate(const Eigen::MatrixXd& U, const BodyVelocity& w, Eigen::MatrixXd& G) const {
  const int n = n_coordinates();
  G.setZero(n, n);
  for (int a = 0; a < n_nodes_; ++a) {
    const Eigen::Vector3d xdot = w.segment<3>(6 * a), omega = w.segment<3>(6 * a + 3);
    G.middleRows<3>(6 * a).noalias() = Skew<double>(xdot) * U;
    if (options_.cardona_option_b) {
      G.block<3, 3>(6 * a + 3, 6 * a + 3) = Skew<double>(omega);
    } else {
      G.middleRows<3>(6 * a + 3).noalias() = Skew<double>(omega) * U;
    }
  }
}

void SuperelementBody::QuadraticInertia(const Eigen::MatrixXd& U, const Eigen::MatrixXd& Mg, const BodyVelocity& w,
                                        Eigen::VectorXd& out, BodyScratch& scratch) const {
  // G = VelocityMapRate(U, w) is never formed: its rows are xdot_a~ U (and omega_a~ U, option A;
  // the diagonal block omega_a~, option B), so G w = [xdot_a x omega_j; omega_a x omega_j (A) or
  // 0 (B); 0] and G^T p = U^T sum_a (p_a x xdot_a + p_rot,a x omega_a (A)) (+ option B:
  // p_rot,a x omega_a on node a's rotation rows).
  const bool B = options_.cardona_option_b;
  Eigen::Vector3d omega_j;
  omega_j.noalias() = U * w;
  Eigen::VectorXd& p = scratch.v1;
  p.noalias() = Mg * w;
  Eigen::VectorXd& Gw = scratch.v2;
  Gw.setZero(n_coordinates());
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  for (int a = 0; a < n_nodes_; ++a) {
    const Eigen::Vector3d xdot = w.segment<3>(6 * a), omega = w.segment<3>(6 * a + 3);
    const Eigen::Vector3d p_x = p.segment<3>(6 * a), p_r = p.segment<3>(6 * a + 3);
    Gw.segment<3>(6 * a) = xdot.cross(omega_j);
    v += p_x.cross(xdot);
    if (!B) {
      Gw.segment<3>(6 * a + 3) = omega.cross(omega_j);
      v += p_r.cross(omega);
    }
  }
  out.noalias() = Mg * Gw;
  out.noalias() -= U.transpose() * v;
  for (int a = 0; a < n_nodes_; ++a) {
    const Eigen::Vector3d omega = w.segment<3>(6 * a + 3);
    const Eigen::Vector3d p_x = p.segment<3>(6 * a), p_r = p.segment<3>(6 * a + 3);
    if (B) out.segment<3>(6 * a + 3) -= p_r.cross(omega);
    // (Omega_P - Omega_hat) p: translation rows omega_j~, rotation rows omega_j~ - omega_a~ (A), 0 (B).
    out.segment<3>(6 * a) += omega_j.cross(p_x);
    if (!B) out.segment<3>(6 * a + 3) += (omega_j - omega).cross(p_r);
  }
}

void SuperelementBody::QuadraticInertiaDerivative(const Eigen::MatrixXd& U, const Eigen::MatrixXd& Mg,
                                                  const BodyVelocity& w, Eigen::MatrixXd& D,
                                                  BodyScratch& scratch) const {
  // g(w) = M_g s(w) - G(w)^T p + (Omega_P - Omega_hat) p, s = G(w) w, p = M_g w; G(w) = L(w) U
  // with L the stacked blocks xdot_a~ (and omega_a~ on the rotation rows, option A), so that
  // every product below is O(n^2). Derivative term by term (d/dw):
  //   M_g ds,   ds rows a: xdot_a x omega_j -> -omega_j~ E_a + xdot_a~ U (rotation rows alike, A;
  //             omega_a x omega_a = 0 for B);
  //   -G^T M_g - Q,  Q = d(G(w)^T p)/dw at fixed p: U^T p_a~ at node a's columns (B: p_rot,a~
  //             on the rotation block);
  //   (Omega_P - Omega_hat) p: -p_a~ U + omega_j~ M_g rows a; rotation rows (A)
  //             -p_rot,a~ (U - E_rot,a) + (omega_j - omega_a)~ M_g rows.
  const int n = n_coordinates();
  const bool B = options_.cardona_option_b;
  Eigen::Vector3d omega_j;
  omega_j.noalias() = U * w;
  Eigen::VectorXd& p = scratch.v1;
  p.noalias() = Mg * w;
  Eigen::MatrixXd& L = scratch.n3a;
  L.setZero(n, 3);
  for (int a = 0; a < n_nodes_; ++a) {
    L.middleRows<3>(6 * a) = Skew<double>(Eigen::Vector3d(w.segment<3>(6 * a)));
    if (!B) L.middleRows<3>(6 * a + 3) = Skew<double>(Eigen::Vector3d(w.segment<3>(6 * a + 3)));
  }
  // ds = L U + N (N: the -omega_j~ blocks on the diagonal); for B the rotation rows of ds vanish.
  Eigen::MatrixXd& MgL = scratch.n3b;
  MgL.noalias() = Mg * L;
  D.resize(n, n);
  D.noalias() = MgL * U;
  const Eigen::Matrix3d Wj = Skew<double>(omega_j);
  for (int a = 0; a < n_nodes_; ++a) {
    D.middleCols<3>(6 * a).noalias() -= Mg.middleCols<3>(6 * a) * Wj;
    if (!B) D.middleCols<3>(6 * a + 3).noalias() -= Mg.middleCols<3>(6 * a + 3) * Wj;
  }
  // -G^T M_g: G = L U (+ for B the diagonal rotation blocks omega_a~).
  Eigen::MatrixXd& LtMg = scratch.n3c;
  LtMg.noalias() = L.transpose() * Mg;
  D.noalias() -= U.transpose() * LtMg;
  for (int a = 0; a < n_nodes_; ++a) {
    const Eigen::Matrix3d Pa = Skew<double>(Eigen::Vector3d(p.segment<3>(6 * a)));
    const Eigen::Matrix3d Pr = Skew<double>(Eigen::Vector3d(p.segment<3>(6 * a + 3)));
    const Eigen::Matrix3d Wa = Skew<double>(Eigen::Vector3d(w.segment<3>(6 * a + 3)));
    if (B) D.middleRows<3>(6 * a + 3).noalias() -= Wa.transpose() * Mg.middleRows<3>(6 * a + 3);
    // -Q.
    D.middleCols<3>(6 * a).noalias() -= U.transpose() * Pa;
    if (B) {
      D.block<3, 3>(6 * a + 3, 6 * a + 3) -= Pr;
    } else {
      D.middleCols<3>(6 * a + 3).noalias() -= U.transpose() * Pr;
    }
    // (Omega_P - Omega_hat) p.
    D.middleRows<3>(6 * a).noalias() -= Pa * U;
    D.middleRows<3>(6 * a).noalias() += Wj * Mg.middleRows<3>(6 * a);
    if (!B) {
      D.middleRows<3>(6 * a + 3).noalias() -= Pr * U;
      D.middleRows<3>(6 * a + 3).noalias() += (Wj - Wa) * Mg.middleRows<3>(6 * a + 3);
      D.block<3, 3>(6 * a + 3, 6 * a + 3) += Pr;
    }
  }
}

const Eigen::VectorXd& SuperelementBody::MassTimes(Data& d, const BodyVelocity& w) const {
  Eigen::VectorXd& p = d.scratch.v1;
  if (has_exact_inertia()) {
    // The exact inertia force's acceleration part at w: M_g w in O(n^2) (the n x n ExactMass
    // costs three n^3 products; the energy measurement of every step took it).
    Eigen::VectorXd& r = d.exact_scratch.r;
    body_blocks::TurnBlocksInto(d.frame.R.transpose(), w, 2 * n_nodes_, r);
    ExactMassTimesTurned(d, r, p);
  } else {
    p.noalias() = MapsOf(d).Mg * w;
  }
  return p;
}

double SuperelementBody::KineticEnergy(Data& d, const BodyVelocity& w) const { return 0.5 * w.dot(MassTimes(d, w)); }

void SuperelementBody::MomentumDerivative(const BodyVelocityMaps& maps, const BodyVelocity& w, Eigen::MatrixXd& D,
                                          BodyScratch& scratch) const {
  const Eigen::MatrixXd& U = maps.U;
  Eigen::VectorXd& p = scratch.v1;
  p.noalias() = maps.Mg * w;
  // dp = dP^T mu + M_g G dq, mu = M P w; P^T turns each node block with R_j (or R_k).
  // M_g G = (M_g L) U (+ option B: M_g's rotation columns times omega_a~), L the stacked
  // xdot_a~ (and omega_a~, option A) of VelocityMapRate: O(n^2) instead of an n x n product.
  const int n = n_coordinates();
  Eigen::MatrixXd& L = scratch.n3a;
  L.setZero(n, 3);
  for (int a = 0; a < n_nodes_; ++a) {
    L.middleRows<3>(6 * a) = Skew<double>(Eigen::Vector3d(w.segment<3>(6 * a)));
    if (!options_.cardona_option_b) L.middleRows<3>(6 * a + 3) = Skew<double>(Eigen::Vector3d(w.segment<3>(6 * a + 3)));
  }
  Eigen::MatrixXd& MgL = scratch.n3b;
  MgL.noalias() = maps.Mg * L;
  D.resize(n, n);
  D.noalias() = MgL * U;
  if (options_.cardona_option_b) {
    for (int a = 0; a < n_nodes_; ++a)
      D.middleCols<3>(6 * a + 3).noalias() +=
          maps.Mg.middleCols<3>(6 * a + 3) * Skew<double>(Eigen::Vector3d(w.segment<3>(6 * a + 3)));
  }
  for (int a = 0; a < n_nodes_; ++a) {
    D.middleRows<3>(6 * a).noalias() -= Skew<double>(Eigen::Vector3d(p.segment<3>(6 * a))) * U;
    const Eigen::Matrix3d p_rot = Skew<double>(Eigen::Vector3d(p.segment<3>(6 * a + 3)));
    if (options_.cardona_option_b) {
      D.block<3, 3>(6 * a + 3, 6 * a + 3) -= p_rot;
    } else {
      D.middleRows<3>(6 * a + 3).noalias() -= p_rot * U;
    }
  }
}

void SuperelementBody::MomentumSourceDerivatives(const BodyVelocityMaps& maps, const BodyVelocity& w,
                                                 const Eigen::VectorXd& p, Eigen::MatrixXd& d_w, Eigen::MatrixXd& d_p,
                                                 BodyScratch& scratch) const {
  const int n = n_coordinates();
  const Eigen::MatrixXd& U = maps.U;
  // s = G(w)^T p + Omega_hat(w) p is bilinear in (w, p).
  Eigen::MatrixXd& G = scratch.nn1;
  VelocityMapRate(U, w, G);
  d_p = G.transpose();
  d_w.setZero(n, n);
  for (int a = 0; a < n_nodes_; ++a) {
    const Eigen::Vector3d omega = w.segment<3>(6 * a + 3);
    d_p.block<3, 3>(6 * a + 3, 6 * a + 3) += Skew<double>(omega);
    // G(e)^T p = U^T (p_x~ e_x + p_pi~ e_pi) (option A); Omega_hat(e) p = -p_pi~ e_pi.
    const Eigen::Matrix3d px = Skew<double>(Eigen::Vector3d(p.segment<3>(6 * a)));
    const Eigen::Matrix3d pr = Skew<double>(Eigen::Vector3d(p.segment<3>(6 * a + 3)));
    d_w.middleCols<3>(6 * a).noalias() += U.transpose() * px;
    if (!options_.cardona_option_b) {
      d_w.middleCols<3>(6 * a + 3).noalias() += U.transpose() * pr;
      d_w.block<3, 3>(6 * a + 3, 6 * a + 3) -= pr;
    }
    // Option B: the node's own G block (p_pi~ e) and Omega_hat(e) p (-p_pi~ e) cancel.
  }
}

void SuperelementBody::MomentumSource(const BodyVelocityMaps& maps, const BodyVelocity& w, const Eigen::VectorXd& p,
                                      Eigen::VectorXd& out, BodyScratch& scratch) const {
  Eigen::MatrixXd& G = scratch.nn1;
  VelocityMapRate(maps.U, w, G);
  out.resize(n_coordinates());
  out.noalias() = G.transpose() * p;
  for (int a = 0; a < n_nodes_; ++a) {
    out.segment<3>(6 * a + 3) +=
        Eigen::Vector3d(w.segment<3>(6 * a + 3)).cross(Eigen::Vector3d(p.segment<3>(6 * a + 3)));
  }
}

void SuperelementBody::MomentumSource(Data& d, const BodyVelocity& w, const Eigen::VectorXd& p,
                                      Eigen::VectorXd& out) const {
  MomentumSource(MapsOf(d), w, p, out, d.scratch);
  if (!has_exact_inertia()) return;
  Eigen::VectorXd& c = d.scratch.v3;
  ExactMomentumSource(d, w, c);
  out += c;
}

}  // namespace femb
