// The momentum balance dp/dt = s(q, w, p) + applied - elastic forces and its derivatives.
#include "solver/body/momentum_source.h"

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

void MomentumSource(const SuperelementBody& body, const BodyVelocityMaps& maps, const BodyVelocity& w,
                    const Eigen::VectorXd& p, Eigen::VectorXd& out, BodyScratch& scratch) {
  Eigen::MatrixXd& G = scratch.nn1;
  VelocityMapRate(body, maps.U, w, G);
  out.resize(body.n_coordinates());
  out.noalias() = G.transpose() * p;
  for (int a = 0; a < body.n_nodes_; ++a) {
    out.segment<3>(6 * a + 3) +=
        Eigen::Vector3d(w.segment<3>(6 * a + 3)).cross(Eigen::Vector3d(p.segment<3>(6 * a + 3)));
  }
}

void MomentumSource(const SuperelementBody& body, BodyData& d, const BodyVelocity& w, const Eigen::VectorXd& p,
                    Eigen::VectorXd& out) {
  MomentumSource(body, MapsOf(body, d), w, p, out, d.scratch);
  if (!body.has_exact_inertia()) return;
  Eigen::VectorXd& c = d.scratch.v3;
  ExactMomentumSource(body, d, w, c);
  out += c;
}

void MomentumSourceDerivatives(const SuperelementBody& body, const BodyVelocityMaps& maps, const BodyVelocity& w,
                               const Eigen::VectorXd& p, Eigen::MatrixXd& d_w, Eigen::MatrixXd& d_p,
                               BodyScratch& scratch) {
  const int n = body.n_coordinates();
  const Eigen::MatrixXd& U = maps.U;
  // s = G(w)^T p + Omega_hat(w) p is bilinear in (w, p).
  Eigen::MatrixXd& G = scratch.nn1;
  VelocityMapRate(body, U, w, G);
  d_p = G.transpose();
  d_w.setZero(n, n);
  for (int a = 0; a < body.n_nodes_; ++a) {
    const Eigen::Vector3d omega = w.segment<3>(6 * a + 3);
    d_p.block<3, 3>(6 * a + 3, 6 * a + 3) += Skew<double>(omega);
    // G(e)^T p = U^T (p_x~ e_x + p_pi~ e_pi) (option A); Omega_hat(e) p = -p_pi~ e_pi.
    const Eigen::Matrix3d px = Skew<double>(Eigen::Vector3d(p.segment<3>(6 * a)));
    const Eigen::Matrix3d pr = Skew<double>(Eigen::Vector3d(p.segment<3>(6 * a + 3)));
    d_w.middleCols<3>(6 * a).noalias() += U.transpose() * px;
    if (!body.options_.cardona_option_b) {
      d_w.middleCols<3>(6 * a + 3).noalias() += U.transpose() * pr;
      d_w.block<3, 3>(6 * a + 3, 6 * a + 3) -= pr;
    }
    // Option B: the node's own G block (p_pi~ e) and Omega_hat(e) p (-p_pi~ e) cancel.
  }
}

void MomentumConfigurationTangent(const SuperelementBody& body, BodyData& d, const BodyVelocity& w, BodyData& side,
                                  Eigen::MatrixXd& D) {
  if (!body.has_exact_inertia()) {
    MomentumDerivative(body, MapsOf(body, d), w, D, d.scratch);
    return;
  }
  // p = Rbar p_hat(q_loc, Rbar^T w): the frame's turning of p is MomentumDerivative's with the
  // exact mass (dp = -p~ U dq + M_e G dq, option A), the local coordinates' share
  // Rbar (d p_hat / d q_loc) B Rbar^T (delta q_loc = B Rbar^T dq), the first factor by central
  // differences in q_loc at the frame of d (no frame solve; steps as Perturbed's).
  const int n = body.n_coordinates(), blocks = 2 * body.n_nodes_;
  BodyVelocityMaps& maps = side.maps;
  maps = MapsOf(body, d);
  maps.Mg = ExactMass(body, d);
  MomentumDerivative(body, maps, w, D, side.scratch);
  double size = 0.0;
  for (const Eigen::Vector3d& X : body.X_) size = std::max(size, X.norm());
  const double length = 1e-7 * std::max(size, 1e-3);
  const double modal = length * std::sqrt(std::max(body.M_(0, 0), 1e-300));
  Eigen::MatrixXd &P = side.exact_scratch.t3, &BR = side.exact_scratch.t4;
  P.resize(n, n);
  side.c = d.c;
  side.q = d.q;
  for (int i = 0; i < n; ++i) {
    const double step = i >= 6 * body.n_nodes_ ? modal : i % 6 < 3 ? length : 1e-7;
    side.q[i] = d.q[i] + step;
    EvaluateSolved(body, side.c, d.frame, side);
    P.col(i) = MassTimes(body, side, w);
    side.q[i] = d.q[i] - step;
    EvaluateSolved(body, side.c, d.frame, side);
    P.col(i) -= MassTimes(body, side, w);
    P.col(i) /= 2 * step;
    side.q[i] = d.q[i];
  }
  BR = d.kin.B;
  const Eigen::Matrix3d Rt = d.frame.R.transpose();
  TurnColBlocks(BR, blocks, [&](int) { return Rt; });
  D.noalias() += P.lazyProduct(BR);  // (no blocking workspace on the heap)
}

void AddLocalSourceVelocityDerivative(const SuperelementBody& body, BodyData& d, const BodyVelocity& w,
                                      Eigen::MatrixXd& d_w) {
  if (!body.has_exact_inertia()) return;
  // c(w) = Q(w, w): c(w + e) - c(w - e) = 4 Q(w, e) = 2 (dc/dw) e for any step e.
  Eigen::VectorXd &wp = d.scratch.v2, &plus = d.scratch.v3, &minus = d.scratch.v4;
  wp = w;
  for (int i = 0; i < body.n_coordinates(); ++i) {
    wp[i] = w[i] + 1.0;
    ExactMomentumSource(body, d, wp, plus);
    wp[i] = w[i] - 1.0;
    ExactMomentumSource(body, d, wp, minus);
    wp[i] = w[i];
    d_w.col(i) += 0.5 * (plus - minus);
  }
}

}  // namespace femb
