// The elastic force and its tangent (thesis 4.12, 4.25-4.37), the polynomial forces, the
// interface constraint and the round-off of the residual.
#include "solver/body/elastic_force.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "solver/body/body_blocks.h"
#include "solver/body/superelement_body.h"
#include "solver/rotation.h"

namespace femb {

using body_blocks::TurnBlocksInto;
using body_blocks::TurnColBlocks;
using body_blocks::TurnNodeBlocks;
using body_blocks::TurnRowBlocks;

double RoundOffForce(const SuperelementBody& body, const BodyConfiguration& c, double inertia_factor) {
  // The positions' size, at least the body's own: a free body by one node at the origin would
  // otherwise have no round-off at all (a torque-free body spinning about a principal axis under
  // the midpoint scheme, whose forces are all round-off, stopped with "Newton diverged").
  double x = body.length();
  for (const Eigen::Vector3d& xk : c.x) x = std::max(x, xk.norm());
  return std::numeric_limits<double>::epsilon() * x *
         (16.0 * std::sqrt(double(body.n_coordinates())) * body.k_nodes_max_ + 4.0 * inertia_factor * body.m_max_);
}

const Eigen::VectorXd& LocalForce(const SuperelementBody& body, BodyData& d, const InertiaLoadFactors* load) {
  // The load factors the force is for (all zero without inertia stiffening: K q alone).
  const Eigen::Matrix<double, 12, 1> a =
      load && !body.K_sigma_.empty() ? load->a : Eigen::Matrix<double, 12, 1>::Zero().eval();
  BodyData::LocalForceOf& kept = d.local_force;
  if (kept.valid && kept.a == a) return kept.Q;
  const Eigen::VectorXd& q = d.q;
  if (body.polynomial_) {
    if (body.polynomial_->cubic()) {
      kept.Q = PolynomialForce(body.K_, *body.polynomial_, q);
    } else {
      CondensedForce(body.K_, *body.polynomial_, q, Condensed(body, d), kept.Q, d.polynomial_scratch);
    }
  } else {
    kept.Q.resize(q.size());
    kept.Q.noalias() = body.K_ * q;
  }
  if (!a.isZero(0.0)) kept.Q.noalias() += SigmaProducts(body, d) * a;
  kept.a = a;
  kept.valid = true;
  return kept.Q;
}

const Eigen::VectorXd& Condensed(const SuperelementBody& body, BodyData& d) {
  if (!d.has_eps) {
    CondensedCoordinates(*body.polynomial_, d.q, d.eps, d.polynomial_scratch);
    d.has_eps = true;
  }
  return d.eps;
}

void LocalTangent(const SuperelementBody& body, BodyData& d, const InertiaLoadFactors* load, Eigen::MatrixXd& K) {
  const Eigen::VectorXd& q = d.q;
  if (!body.polynomial_) {
    K = body.K_;
  } else if (body.polynomial_->cubic()) {
    K = PolynomialTangent(body.K_, *body.polynomial_, q);
  } else {
    CondensedTangent(body.K_, *body.polynomial_, q, Condensed(body, d), K, d.polynomial_scratch);
  }
  if (load && !body.K_sigma_.empty()) {
    for (int k = 0; k < kInertiaLoadCaseCount; ++k)
      if (load->a[k] != 0.0) K += load->a[k] * body.K_sigma_[size_t(k)];
  }
}

double ElasticEnergy(const SuperelementBody& body, BodyData& d) {
  const Eigen::VectorXd& q = d.q;
  if (body.polynomial_ && body.polynomial_->cubic()) return PolynomialEnergy(body.K_, *body.polynomial_, q);
  // Linear: q^T K q / 2; the condensed polynomial: eps^T K eps / 2 with the data's eps.
  const Eigen::VectorXd& e = body.polynomial_ ? Condensed(body, d) : q;
  Eigen::VectorXd& Ke = d.scratch.v1;
  Ke.noalias() = body.K_ * e;
  return 0.5 * e.dot(Ke);
}

void AddGeometricTangent(const SuperelementBody& body, BodyData& d, const Eigen::VectorXd& Q,
                         const Eigen::VectorXd& Qhat, bool approximated, Eigen::MatrixXd& Kt) {
  const int n = body.n_coordinates();
  const Eigen::VectorXd& q = d.q;
  const BodyKinematics& kin = d.kin;
  // Fhat, Mhat (n x 6) from Qhat: node rows [0, F~; 0, 0] and [0, 0; 0, M~].
  Eigen::MatrixXd &Fhat = d.scratch.n6a, &FMhat = d.scratch.n6b;
  Fhat.setZero(n, 6);
  FMhat.setZero(n, 6);
  for (int a = 0; a < body.n_nodes_; ++a) {
    const Eigen::Matrix3d F = Skew<double>(Eigen::Vector3d(Qhat.segment<3>(6 * a)));
    Fhat.block<3, 3>(6 * a, 3) = F;
    FMhat.block<3, 3>(6 * a, 3) = F;
    FMhat.block<3, 3>(6 * a + 3, 3) = Skew<double>(Eigen::Vector3d(Qhat.segment<3>(6 * a + 3)));
  }
  Kt.noalias() -= FMhat * kin.Z;  // K3: rotation of the frame
  if (!approximated) {
    Eigen::MatrixXd& FtB = d.scratch.n6c;  // 6 x n first
    FtB.noalias() = Fhat.transpose() * kin.B;
    Kt.noalias() -= kin.Z.transpose() * FtB;  // K2: variation of Phi_rig in T
    // K4: variation of D (exact rotation kinematics), v = P^T Q, P = 1 - D Phi_rig S^-1 Phi_CB.
    Eigen::VectorXd& DtQ = d.scratch.v1;  // D^T Q
    DtQ = Q;
    for (int a = 0; a < body.n_nodes_; ++a)
      DtQ.segment<3>(6 * a + 3) = kin.Jinv[size_t(a)].transpose() * Q.segment<3>(6 * a + 3);
    Eigen::Matrix<double, 6, 1> PtDtQ;
    PtDtQ.noalias() = kin.Phi_rig.transpose() * DtQ;
    const Eigen::Matrix<double, 6, 1> SPtDtQ = kin.S_inv.transpose() * PtDtQ;
    Eigen::VectorXd& v = d.scratch.v2;
    v = Q;
    v.noalias() -= body.Phi_CB_.transpose() * SPtDtQ;
    // G is block diagonal (a 3 x 3 block per node rotation): T^T G B = sum_a T_a^T (G_a B_a)
    // with T_a, B_a node a's rotation rows.
    Eigen::MatrixXd& GB = d.scratch.n3a;
    GB.resize(3, n);
    for (int a = 0; a < body.n_nodes_; ++a) {
      const Eigen::Matrix3d G = LeftJacobianInverseTransposeDerivative(Eigen::Vector3d(q.segment<3>(6 * a + 3)),
                                                                       Eigen::Vector3d(v.segment<3>(6 * a + 3)));
      GB.noalias() = G * kin.B.middleRows<3>(6 * a + 3);
      Kt.noalias() += kin.T.middleRows<3>(6 * a + 3).transpose() * GB;
    }
  }
}

void ElasticForce(const SuperelementBody& body, BodyData& d, Eigen::VectorXd* f, Eigen::MatrixXd* tangent,
                  const InertiaLoadFactors* load, Eigen::MatrixXd* d_load) {
  const int n = body.n_coordinates();
  const BodyKinematics& kin = d.kin;
  const FrameSolution& frame = d.frame;
  if (!load || body.K_sigma_.empty()) load = nullptr;
  const Eigen::VectorXd& Q = LocalForce(body, d, load);
  Eigen::VectorXd& Qhat = d.scratch.v3;  // B^T Q (T0^T Q approximated)
  Qhat.resize(n);
  if (body.options_.approximated) {
    Qhat.noalias() = body.T0_.transpose() * Q;
  } else {
    Qhat.noalias() = kin.B.transpose() * Q;
  }
  // Rbar: R_j on every node's force and moment, identity on modal rows.
  if (f) TurnBlocksInto(frame.R, Qhat, 2 * body.n_nodes_, *f);
  if (d_load) {
    if (load) {
      // Rbar B^T [K_sigma,k q]: node rows turned by R_j.
      d_load->resize(n, kInertiaLoadCaseCount);
      if (body.options_.approximated) {
        d_load->noalias() = body.T0_.transpose() * SigmaProducts(body, d);
      } else {
        d_load->noalias() = kin.B.transpose() * SigmaProducts(body, d);
      }
      TurnRowBlocks(*d_load, 2 * body.n_nodes_, [&](int) { return frame.R; });
    } else {
      d_load->setZero(n, kInertiaLoadCaseCount);
    }
  }
  if (!tangent) return;

  Eigen::MatrixXd& Kt = *tangent;  // written in place: a kept tangent's storage is reused
  const Eigen::MatrixXd* Kq = &body.K_;
  if (body.polynomial_ || (load && !body.K_sigma_.empty())) {
    LocalTangent(body, d, load, d.scratch.nn1);
    Kq = &d.scratch.nn1;
  }
  Eigen::MatrixXd& KB = d.scratch.nn2;
  KB.noalias() = *Kq * kin.B;
  Kt.resize(n, n);
  if (body.options_.approximated) {
    Kt.noalias() = body.T0_.transpose() * KB;
  } else {
    Kt.noalias() = kin.B.transpose() * KB;  // K1
  }
  if (body.options_.full_tangent) AddGeometricTangent(body, d, Q, Qhat, body.options_.approximated, Kt);
  // Rbar Kt Rbar^T, block by block.
  TurnNodeBlocks(Kt, 2 * body.n_nodes_, frame.R);
}

void InterfaceConstraint(const SuperelementBody& body, BodyData& d, Eigen::VectorXd* g, Eigen::MatrixXd* G,
                         const Eigen::VectorXd* lambda, Eigen::MatrixXd* H) {
  const int n = body.n_coordinates(), r = body.n_constraints(), nb = 6 * body.n_nodes_;
  const Eigen::Matrix3d R = d.frame.R, Rt = d.frame.R.transpose();
  if (g) {
    g->resize(r);
    g->noalias() = body.C_ * d.q.head(nb);
  }
  if (G) {
    // d q_loc = B Rbar^T dq (exact, also with the approximated option: this is a constraint).
    G->resize(r, n);
    G->noalias() = body.C_ * d.kin.B.topRows(nb);
    TurnColBlocks(*G, 2 * body.n_nodes_, [&](int) { return Rt; });
  }
  if (!H) return;
  // G^T lambda = Rbar B^T Q with Q = C^T lambda (zero on the modal rows): the elastic force's
  // form with a local force that does not depend on the configuration, so its derivative is
  // K2 + K3 + K4 of that Q (no K1).
  Eigen::VectorXd &Q = d.scratch.v4, &Qhat = d.scratch.v3;  // (AddGeometricTangent takes v1, v2)
  Q.setZero(n);
  Q.head(nb).noalias() = body.C_.transpose() * *lambda;
  Qhat.resize(n);
  Qhat.noalias() = d.kin.B.transpose() * Q;
  H->setZero(n, n);
  AddGeometricTangent(body, d, Q, Qhat, false, *H);
  TurnNodeBlocks(*H, 2 * body.n_nodes_, R);
}

}  // namespace femb
