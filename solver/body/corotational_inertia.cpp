// The corotational inertia (thesis 3.22, 4.9-4.11): the velocity maps, their rates, the
// quadratic inertia terms and the momentum's configuration derivative.
#include "solver/body/corotational_inertia.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "solver/body/body_blocks.h"
#include "solver/body/superelement_body.h"
#include "solver/rotation.h"

namespace femb {

using body_blocks::TurnColBlocks;
using body_blocks::TurnRowBlocks;

const BodyVelocityMaps& MapsOf(const SuperelementBody& body, BodyData& d) {
  if (!d.has_maps) {
    BodyVelocityMaps& maps = d.maps;
    VelocityMaps(body, d, &maps.P, &maps.U);
    // M_g = P^T M P with P block diagonal (3 x 3 blocks, then 1 on the modal rows).
    maps.Mg = body.M_;
    TurnRowBlocks(maps.Mg, 2 * body.n_nodes_,
                  [&](int a) { return Eigen::Matrix3d(maps.P.block<3, 3>(3 * a, 3 * a).transpose()); });
    TurnColBlocks(maps.Mg, 2 * body.n_nodes_, [&](int a) { return Eigen::Matrix3d(maps.P.block<3, 3>(3 * a, 3 * a)); });
    d.has_maps = true;
  }
  return d.maps;
}

void VelocityMaps(const SuperelementBody& body, BodyData& d, Eigen::MatrixXd* P, Eigen::MatrixXd* U) {
  const int n = body.n_coordinates();
  const BodyConfiguration& c = d.c;
  const FrameSolution& frame = d.frame;
  const BodyKinematics& kin = d.kin;
  P->setIdentity(n, n);
  for (int a = 0; a < body.n_nodes_; ++a) {
    P->block<3, 3>(6 * a, 6 * a) = frame.R.transpose();
    P->block<3, 3>(6 * a + 3, 6 * a + 3) = body.options_.cardona_option_b ? c.R[a].transpose() : frame.R.transpose();
  }
  // Spatial variation of the frame rotation: d pi_j = R_j (Z Rbar^T dq)_rot (thesis 3.17).
  Eigen::MatrixXd& Zr = d.scratch.n3a;
  Zr = kin.Z.bottomRows<3>();
  const Eigen::Matrix3d Rt = frame.R.transpose();
  TurnColBlocks(Zr, 2 * body.n_nodes_, [&](int) { return Rt; });
  U->resize(3, n);
  U->noalias() = frame.R * Zr;
}

void VelocityMapRate(const SuperelementBody& body, const Eigen::MatrixXd& U, const BodyVelocity& w,
                     Eigen::MatrixXd& G) {
  const int n = body.n_coordinates();
  G.setZero(n, n);
  for (int a = 0; a < body.n_nodes_; ++a) {
    const Eigen::Vector3d xdot = w.segment<3>(6 * a), omega = w.segment<3>(6 * a + 3);
    G.middleRows<3>(6 * a).noalias() = Skew<double>(xdot) * U;
    if (body.options_.cardona_option_b) {
      G.block<3, 3>(6 * a + 3, 6 * a + 3) = Skew<double>(omega);
    } else {
      G.middleRows<3>(6 * a + 3).noalias() = Skew<double>(omega) * U;
    }
  }
}

void QuadraticInertia(const SuperelementBody& body, const Eigen::MatrixXd& U, const Eigen::MatrixXd& Mg,
                      const BodyVelocity& w, Eigen::VectorXd& out, BodyScratch& scratch) {
  // G = VelocityMapRate(body, U, w) is never formed: its rows are xdot_a~ U (and omega_a~ U, option A;
  // the diagonal block omega_a~, option B), so G w = [xdot_a x omega_j; omega_a x omega_j (A) or
  // 0 (B); 0] and G^T p = U^T sum_a (p_a x xdot_a + p_rot,a x omega_a (A)) (+ option B:
  // p_rot,a x omega_a on node a's rotation rows).
  const bool B = body.options_.cardona_option_b;
  Eigen::Vector3d omega_j;
  omega_j.noalias() = U * w;
  Eigen::VectorXd& p = scratch.v1;
  p.noalias() = Mg * w;
  Eigen::VectorXd& Gw = scratch.v2;
  Gw.setZero(body.n_coordinates());
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  for (int a = 0; a < body.n_nodes_; ++a) {
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
  for (int a = 0; a < body.n_nodes_; ++a) {
    const Eigen::Vector3d omega = w.segment<3>(6 * a + 3);
    const Eigen::Vector3d p_x = p.segment<3>(6 * a), p_r = p.segment<3>(6 * a + 3);
    if (B) out.segment<3>(6 * a + 3) -= p_r.cross(omega);
    // (Omega_P - Omega_hat) p: translation rows omega_j~, rotation rows omega_j~ - omega_a~ (A), 0 (B).
    out.segment<3>(6 * a) += omega_j.cross(p_x);
    if (!B) out.segment<3>(6 * a + 3) += (omega_j - omega).cross(p_r);
  }
}

void QuadraticInertiaDerivative(const SuperelementBody& body, const Eigen::MatrixXd& U, const Eigen::MatrixXd& Mg,
                                const BodyVelocity& w, Eigen::MatrixXd& D, BodyScratch& scratch) {
  // g(w) = M_g s(w) - G(w)^T p + (Omega_P - Omega_hat) p, s = G(w) w, p = M_g w; G(w) = L(w) U
  // with L the stacked blocks xdot_a~ (and omega_a~ on the rotation rows, option A), so that
  // every product below is O(n^2). Derivative term by term (d/dw):
  //   M_g ds,   ds rows a: xdot_a x omega_j -> -omega_j~ E_a + xdot_a~ U (rotation rows alike, A;
  //             omega_a x omega_a = 0 for B);
  //   -G^T M_g - Q,  Q = d(G(w)^T p)/dw at fixed p: U^T p_a~ at node a's columns (B: p_rot,a~
  //             on the rotation block);
  //   (Omega_P - Omega_hat) p: -p_a~ U + omega_j~ M_g rows a; rotation rows (A)
  //             -p_rot,a~ (U - E_rot,a) + (omega_j - omega_a)~ M_g rows.
  const int n = body.n_coordinates();
  const bool B = body.options_.cardona_option_b;
  Eigen::Vector3d omega_j;
  omega_j.noalias() = U * w;
  Eigen::VectorXd& p = scratch.v1;
  p.noalias() = Mg * w;
  Eigen::MatrixXd& L = scratch.n3a;
  L.setZero(n, 3);
  for (int a = 0; a < body.n_nodes_; ++a) {
    L.middleRows<3>(6 * a) = Skew<double>(Eigen::Vector3d(w.segment<3>(6 * a)));
    if (!B) L.middleRows<3>(6 * a + 3) = Skew<double>(Eigen::Vector3d(w.segment<3>(6 * a + 3)));
  }
  // ds = L U + N (N: the -omega_j~ blocks on the diagonal); for B the rotation rows of ds vanish.
  Eigen::MatrixXd& MgL = scratch.n3b;
  MgL.noalias() = Mg * L;
  D.resize(n, n);
  D.noalias() = MgL * U;
  const Eigen::Matrix3d Wj = Skew<double>(omega_j);
  for (int a = 0; a < body.n_nodes_; ++a) {
    D.middleCols<3>(6 * a).noalias() -= Mg.middleCols<3>(6 * a) * Wj;
    if (!B) D.middleCols<3>(6 * a + 3).noalias() -= Mg.middleCols<3>(6 * a + 3) * Wj;
  }
  // -G^T M_g: G = L U (+ for B the diagonal rotation blocks omega_a~).
  Eigen::MatrixXd& LtMg = scratch.n3c;
  LtMg.noalias() = L.transpose() * Mg;
  D.noalias() -= U.transpose() * LtMg;
  for (int a = 0; a < body.n_nodes_; ++a) {
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

void MomentumDerivative(const SuperelementBody& body, const BodyVelocityMaps& maps, const BodyVelocity& w,
                        Eigen::MatrixXd& D, BodyScratch& scratch) {
  const Eigen::MatrixXd& U = maps.U;
  Eigen::VectorXd& p = scratch.v1;
  p.noalias() = maps.Mg * w;
  // dp = dP^T mu + M_g G dq, mu = M P w; P^T turns each node block with R_j (or R_k).
  // M_g G = (M_g L) U (+ option B: M_g's rotation columns times omega_a~), L the stacked
  // xdot_a~ (and omega_a~, option A) of VelocityMapRate: O(n^2) instead of an n x n product.
  const int n = body.n_coordinates();
  Eigen::MatrixXd& L = scratch.n3a;
  L.setZero(n, 3);
  for (int a = 0; a < body.n_nodes_; ++a) {
    L.middleRows<3>(6 * a) = Skew<double>(Eigen::Vector3d(w.segment<3>(6 * a)));
    if (!body.options_.cardona_option_b)
      L.middleRows<3>(6 * a + 3) = Skew<double>(Eigen::Vector3d(w.segment<3>(6 * a + 3)));
  }
  Eigen::MatrixXd& MgL = scratch.n3b;
  MgL.noalias() = maps.Mg * L;
  D.resize(n, n);
  D.noalias() = MgL * U;
  if (body.options_.cardona_option_b) {
    for (int a = 0; a < body.n_nodes_; ++a)
      D.middleCols<3>(6 * a + 3).noalias() +=
          maps.Mg.middleCols<3>(6 * a + 3) * Skew<double>(Eigen::Vector3d(w.segment<3>(6 * a + 3)));
  }
  for (int a = 0; a < body.n_nodes_; ++a) {
    D.middleRows<3>(6 * a).noalias() -= Skew<double>(Eigen::Vector3d(p.segment<3>(6 * a))) * U;
    const Eigen::Matrix3d p_rot = Skew<double>(Eigen::Vector3d(p.segment<3>(6 * a + 3)));
    if (body.options_.cardona_option_b) {
      D.block<3, 3>(6 * a + 3, 6 * a + 3) -= p_rot;
    } else {
      D.middleRows<3>(6 * a + 3).noalias() -= p_rot * U;
    }
  }
}

}  // namespace femb
