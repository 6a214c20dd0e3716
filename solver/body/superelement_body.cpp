#include "solver/body/superelement_body.h"

#include <Eigen/Dense>
#include <array>
#include <limits>

#include "formats/input_error.h"
#include "solver/body/body_blocks.h"
#include "solver/rotation.h"

namespace femb {
using body_blocks::TurnBlocksInto;
using body_blocks::TurnColBlocks;
using body_blocks::TurnNodeBlocks;
using body_blocks::TurnRowBlocks;

SuperelementBody::SuperelementBody(const Superelement& se, const SuperelementOptions& options,
                                   const Eigen::Matrix3d& placement_R, const Eigen::Vector3d& placement_x)
    : n_nodes_(se.n_interface_nodes()),
      n_modes_(se.n_reduced_dofs() - se.n_interface_dofs()),
      options_(options),
      K_(se.K),
      M_(se.M),
      Phi_CB_(se.floating_frame.Phi_CB),
      C_(se.interface_constraint.rows() > 0 ? se.interface_constraint : Eigen::MatrixXd(0, 6 * se.n_interface_nodes())),
      placement_R_(placement_R),
      placement_x_(placement_x),
      origin_part_(se.floating_frame.origin) {
  if (!se.floating_frame.orientation.isIdentity(1e-12)) {
    throw InputError(se.name + ": floating frame orientation other than the part axes is not supported");
  }
  for (const InterfaceNode& node : se.interfaces) {
    X_.push_back(node.position - se.floating_frame.origin);
    R0_.push_back(node.orientation);
  }
  Phi_rig0_ = RigidBodyModes(se, se.floating_frame.origin);
  {
    // CenterOfMass's constants. Phi_rig0^T M Phi_rig0 = [m 1, -s~; s~, J]: the first moment s
    // from its (translation, rotation) block -s~ (entry (b, 3 + a) = e_b . (e_a x s)).
    const Eigen::MatrixXd MPhi = M_ * Phi_rig0_;
    const Eigen::Matrix<double, 6, 6> M_rig = Phi_rig0_.transpose() * MPhi;
    mass_ = M_rig(0, 0);
    first_moment0_ = Eigen::Vector3d(-M_rig(2, 4), -M_rig(0, 5), -M_rig(1, 3));
    first_moment_map_ = MPhi.leftCols<3>().transpose();
  }
  T0_ = Eigen::MatrixXd::Identity(n_coordinates(), n_coordinates()) - Phi_rig0_ * Phi_CB_;
  double size = 0.0;
  for (const Eigen::Vector3d& X : X_) size = std::max(size, X.norm());
  // Force units in any unit system (ForceNorm): moments over a length of the body (its size, or
  // for a one-node body its radius of gyration), modal forces times sqrt(mass).
  const double mass = (Phi_rig0_.col(0).transpose() * M_ * Phi_rig0_.col(0))(0, 0);
  const Eigen::Matrix<double, 6, 6> M_rig = Phi_rig0_.transpose() * M_ * Phi_rig0_;
  const double gyration = mass > 0 ? std::sqrt(M_rig.bottomRightCorner<3, 3>().diagonal().maxCoeff() / mass) : 0.0;
  const double length = size > 0 ? size : (gyration > 0 ? gyration : 1.0);
  force_weights_ = Eigen::VectorXd::Ones(n_coordinates());
  for (int k = 0; k < n_nodes_; ++k) force_weights_.segment<3>(6 * k + 3).setConstant(1.0 / length);
  modal_weight_ = std::sqrt(std::max(mass, 0.0));
  force_weights_.tail(n_modes_).setConstant(modal_weight_);
  k_max_ = (force_weights_.asDiagonal() * K_ * force_weights_.asDiagonal()).cwiseAbs().maxCoeff();
  m_max_ = (force_weights_.asDiagonal() * M_ * force_weights_.asDiagonal()).cwiseAbs().maxCoeff();
  force_floor_ = 1e-4 * k_max_ * length;
  // A file's polynomial is the modal derivatives' cubic force (option polynomial_force) or,
  // without derivatives, the geometric stiffening's quadratic force (option geometric_stiffening).
  if (se.polynomial && (se.polynomial->cubic() ? options_.polynomial_force : options_.geometric_stiffening)) {
    polynomial_ = WithCondensation(K_, *se.polynomial);
  }
  const int n = n_coordinates();
  if (options_.geometric_stiffening) {
    K_sigma_ = se.inertia_stiffness;
    if (!K_sigma_.empty()) {
      K_sigma_stack_.resize(kInertiaLoadCaseCount * n, n);
      for (int k = 0; k < kInertiaLoadCaseCount; ++k) K_sigma_stack_.middleRows(k * n, n) = K_sigma_[size_t(k)];
    }
  }
  if (options_.exact_inertia && se.inertia_gamma.size() == 3 && se.inertia_xi.size() == 6) {
    // Cardona's options are two forms of the corotational inertia; the exact kinetic energy has
    // one, whose frame-turning terms (the maps and sources of the midpoint scheme) are option A's.
    options_.cardona_option_b = false;
    Gamma_ = se.inertia_gamma;
    Gamma_stack_.resize(3 * n, n);
    for (int a = 0; a < 3; ++a) Gamma_stack_.middleRows(a * n, n) = Gamma_[size_t(a)];
    const int stored[3][3] = {{0, 3, 4}, {3, 1, 5}, {4, 5, 2}};  // xx yy zz xy xz yz
    Xi_stack_.resize(9 * n, n);
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        const Eigen::MatrixXd& X = se.inertia_xi[size_t(stored[a][b])];
        if (a <= b) {
          Xi_stack_.middleRows((3 * a + b) * n, n) = X;
        } else {
          Xi_stack_.middleRows((3 * a + b) * n, n) = X.transpose();
        }
      }
    PtM_ = Phi_rig0_.transpose() * M_;
  }
  initial_frame_.x = placement_x_ + placement_R_ * origin_part_;
  initial_frame_.R = placement_R_;
  initial_frame_.ok = true;
}

BodyConfiguration SuperelementBody::InitialConfiguration() const {
  BodyConfiguration c;
  for (int k = 0; k < n_nodes_; ++k) {
    c.x.push_back(placement_x_ + placement_R_ * (origin_part_ + X_[k]));
    c.R.push_back(placement_R_ * R0_[k]);
  }
  c.eta = Eigen::VectorXd::Zero(n_modes_);
  return c;
}

namespace {

// The inverse of a 6 x 6 matrix (the frame matrix S) by Gauss-Jordan elimination with partial
// pivoting, on fixed-size storage: Eigen's PartialPivLU::inverse goes through its general
// triangular solves, 3% of a step of the peer slider-crank (perf).
Eigen::Matrix<double, 6, 6> Inverse6(Eigen::Matrix<double, 6, 6> A) {
  Eigen::Matrix<double, 6, 6> X = Eigen::Matrix<double, 6, 6>::Identity();
  for (int k = 0; k < 6; ++k) {
    int p = k;
    for (int i = k + 1; i < 6; ++i)
      if (std::abs(A(i, k)) > std::abs(A(p, k))) p = i;
    if (p != k) {
      A.row(k).swap(A.row(p));
      X.row(k).swap(X.row(p));
    }
    const double pivot = 1.0 / A(k, k);
    A.row(k) *= pivot;
    X.row(k) *= pivot;
    for (int i = 0; i < 6; ++i) {
      const double f = A(i, k);
      if (i == k || f == 0.0) continue;
      A.row(i) -= f * A.row(k);
      X.row(i) -= f * X.row(k);
    }
  }
  return X;
}

}  // namespace

void SuperelementBody::ComputeKinematics(const Eigen::VectorXd& q, Kinematics& k) const {
  const int n = n_coordinates();
  k.Phi_rig.setZero(n, 6);
  // D is block diagonal and Phi_rig is a [1, -r_a~; 0, 1] block per node: every product below
  // goes node block by node block (O(n) per block, no n^3 or dense n x n products).
  std::vector<Eigen::Matrix3d>& Jinv = k.Jinv;
  Jinv.resize(static_cast<size_t>(n_nodes_));
  Eigen::MatrixXd& W = k.W;
  W = Phi_CB_;  // Phi_CB D
  k.S.setZero();
  for (int a = 0; a < n_nodes_; ++a) {
    const Eigen::Matrix3d r_skew = Skew<double>(Eigen::Vector3d(X_[a] + q.segment<3>(6 * a)));
    auto block = k.Phi_rig.block<6, 6>(6 * a, 0);
    block.setIdentity();
    block.block<3, 3>(0, 3) = -r_skew;
    Jinv[size_t(a)] = LeftJacobianInverse<double>(Eigen::Vector3d(q.segment<3>(6 * a + 3)));
    W.middleCols<3>(6 * a + 3).noalias() = Phi_CB_.middleCols<3>(6 * a + 3) * Jinv[size_t(a)];
    // S = Phi_CB D Phi_rig = W Phi_rig (FrameMatrix, with D's blocks at hand).
    k.S.leftCols<3>() += W.middleCols<3>(6 * a);
    Eigen::Matrix<double, 6, 3> Wr;  // fixed size: no temporary on the heap
    Wr.noalias() = W.middleCols<3>(6 * a) * r_skew;
    k.S.rightCols<3>() += W.middleCols<3>(6 * a + 3) - Wr;
  }
  // S^-1 once (Inverse6); Z and the elastic tangent's K4 take fixed-size products with it
  // instead of a triangular solve with n right-hand sides each.
  k.S_inv = Inverse6(k.S);
  k.Z.resize(6, n);
  using Rows6 = Eigen::Matrix<double, 6, Eigen::Dynamic>;  // fixed rows: the product unrolls over them
  Eigen::Map<Rows6>(k.Z.data(), 6, n).noalias() = k.S_inv * Eigen::Map<const Rows6>(W.data(), 6, n);
  // T = 1 - Phi_rig Z: node a's translation rows minus (Z_t - r_a~ Z_r), rotation rows minus Z_r
  // (Z_t, Z_r the frame's translation and rotation rows of Z); B = D T: the rotation rows turned.
  k.T.setIdentity(n, n);
  const auto Zt = k.Z.topRows<3>(), Zr = k.Z.bottomRows<3>();
  for (int a = 0; a < n_nodes_; ++a) {
    const Eigen::Matrix3d r_skew = Skew<double>(Eigen::Vector3d(X_[a] + q.segment<3>(6 * a)));
    k.T.middleRows<3>(6 * a) -= Zt;
    k.T.middleRows<3>(6 * a).noalias() += r_skew * Zr;
    k.T.middleRows<3>(6 * a + 3) -= Zr;
  }
  k.B = k.T;
  for (int a = 0; a < n_nodes_; ++a)
    k.B.middleRows<3>(6 * a + 3).noalias() = Jinv[size_t(a)] * k.T.middleRows<3>(6 * a + 3);
}

SuperelementBody::Data SuperelementBody::Evaluate(const BodyConfiguration& c, const FrameSolution& frame) const {
  Data d;
  Evaluate(c, frame, d);
  return d;
}

void SuperelementBody::Evaluate(const BodyConfiguration& c, const FrameSolution& frame, Data& d) const {
  LocalCoordinates(c, frame, d.q);
  EvaluateSolved(c, frame, d);
}

void SuperelementBody::EvaluateSolved(const BodyConfiguration& c, const FrameSolution& frame, Data& d) const {
  if (&c != &d.c) d.c = c;
  d.frame = frame;
  ComputeKinematics(d.q, d.kin);
  if (has_exact_inertia()) {
    if (!d.exact) d.exact.emplace();
    Exact(d.q, d.kin, *d.exact);
  } else {
    d.exact.reset();
  }
  d.has_maps = false;
  d.local_force.valid = false;
  d.has_exact_mass = false;
  d.has_sigma_q = false;
  d.has_eps = false;
}

double SuperelementBody::RoundOffForce(const BodyConfiguration& c, double inertia_factor) const {
  double x = 0.0;
  for (const Eigen::Vector3d& xk : c.x) x = std::max(x, xk.norm());
  return std::numeric_limits<double>::epsilon() * x *
         (16.0 * std::sqrt(double(n_coordinates())) * k_max_ + 4.0 * inertia_factor * m_max_);
}

const Eigen::MatrixXd& SuperelementBody::SigmaProducts(Data& d) const {
  if (!d.has_sigma_q) {
    const int n = n_coordinates();
    // The stacked product K_sigma q (12 n) is the n x 12 matrix column by column.
    d.sigma_q.resize(n, kInertiaLoadCaseCount);
    Eigen::Map<Eigen::VectorXd>(d.sigma_q.data(), Eigen::Index(n) * kInertiaLoadCaseCount).noalias() =
        K_sigma_stack_ * d.q;
    d.has_sigma_q = true;
  }
  return d.sigma_q;
}

const Eigen::VectorXd& SuperelementBody::LocalForce(Data& d, const InertiaLoadFactors* load) const {
  // The load factors the force is for (all zero without inertia stiffening: K q alone).
  const Eigen::Matrix<double, 12, 1> a =
      load && !K_sigma_.empty() ? load->a : Eigen::Matrix<double, 12, 1>::Zero().eval();
  Data::LocalForceOf& kept = d.local_force;
  if (kept.valid && kept.a == a) return kept.Q;
  const Eigen::VectorXd& q = d.q;
  if (polynomial_) {
    if (polynomial_->cubic()) {
      kept.Q = PolynomialForce(K_, *polynomial_, q);
    } else {
      CondensedForce(K_, *polynomial_, q, Condensed(d), kept.Q, d.polynomial_scratch);
    }
  } else {
    kept.Q.resize(q.size());
    kept.Q.noalias() = K_ * q;
  }
  if (!a.isZero(0.0)) kept.Q.noalias() += SigmaProducts(d) * a;
  kept.a = a;
  kept.valid = true;
  return kept.Q;
}

const Eigen::VectorXd& SuperelementBody::Condensed(Data& d) const {
  if (!d.has_eps) {
    CondensedCoordinates(*polynomial_, d.q, d.eps, d.polynomial_scratch);
    d.has_eps = true;
  }
  return d.eps;
}

void SuperelementBody::LocalTangent(Data& d, const InertiaLoadFactors* load, Eigen::MatrixXd& K) const {
  const Eigen::VectorXd& q = d.q;
  if (!polynomial_) {
    K = K_;
  } else if (polynomial_->cubic()) {
    K = PolynomialTangent(K_, *polynomial_, q);
  } else {
    CondensedTangent(K_, *polynomial_, q, Condensed(d), K, d.polynomial_scratch);
  }
  if (load && !K_sigma_.empty()) {
    for (int k = 0; k < kInertiaLoadCaseCount; ++k)
      if (load->a[k] != 0.0) K += load->a[k] * K_sigma_[size_t(k)];
  }
}

void SuperelementBody::InertiaLoads(Data& d, const BodyVelocity& w, const BodyVelocity& wdot,
                                    const Eigen::Vector3d& gravity, InertiaLoadFactors& out) const {
  const int n = n_coordinates();
  out.d_w.setZero(12, n);
  out.d_wdot.setZero(12, n);
  const Eigen::VectorXd& q = d.q;
  const Kinematics& kin = d.kin;
  const FrameSolution& frame = d.frame;
  // Z Rbar^T: node vectors to frame axes, then the frame's part.
  Eigen::MatrixXd& ZR = d.scratch.n6a;
  ZR = kin.Z;
  const Eigen::Matrix3d Rt = frame.R.transpose();
  for (int a = 0; a < 2 * n_nodes_; ++a) ZR.middleCols<3>(3 * a).noalias() = kin.Z.middleCols<3>(3 * a) * Rt;
  const Eigen::Vector3d omega = ZR.bottomRows<3>() * w;
  const auto d_omega = ZR.bottomRows<3>();  // 3 x n
  // Node accelerations in frame axes minus the centrifugal part of the rigid motion.
  Eigen::Matrix<double, 6, 1> acc = ZR * wdot;
  Eigen::Matrix<double, 6, 3> d_acc_d_omega = Eigen::Matrix<double, 6, 3>::Zero();
  for (int a = 0; a < n_nodes_; ++a) {
    const Eigen::Vector3d r = X_[a] + q.segment<3>(6 * a);
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

double SuperelementBody::ElasticEnergy(Data& d) const {
  const Eigen::VectorXd& q = d.q;
  if (polynomial_ && polynomial_->cubic()) return PolynomialEnergy(K_, *polynomial_, q);
  // Linear: q^T K q / 2; the condensed polynomial: eps^T K eps / 2 with the data's eps.
  const Eigen::VectorXd& e = polynomial_ ? Condensed(d) : q;
  Eigen::VectorXd& Ke = d.scratch.v1;
  Ke.noalias() = K_ * e;
  return 0.5 * e.dot(Ke);
}

void SuperelementBody::AddGeometricTangent(Data& d, const Eigen::VectorXd& Q, const Eigen::VectorXd& Qhat,
                                           bool approximated, Eigen::MatrixXd& Kt) const {
  const int n = n_coordinates();
  const Eigen::VectorXd& q = d.q;
  const Kinematics& kin = d.kin;
  // Fhat, Mhat (n x 6) from Qhat: node rows [0, F~; 0, 0] and [0, 0; 0, M~].
  Eigen::MatrixXd &Fhat = d.scratch.n6a, &FMhat = d.scratch.n6b;
  Fhat.setZero(n, 6);
  FMhat.setZero(n, 6);
  for (int a = 0; a < n_nodes_; ++a) {
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
    for (int a = 0; a < n_nodes_; ++a)
      DtQ.segment<3>(6 * a + 3) = kin.Jinv[size_t(a)].transpose() * Q.segment<3>(6 * a + 3);
    Eigen::Matrix<double, 6, 1> PtDtQ;
    PtDtQ.noalias() = kin.Phi_rig.transpose() * DtQ;
    const Eigen::Matrix<double, 6, 1> SPtDtQ = kin.S_inv.transpose() * PtDtQ;
    Eigen::VectorXd& v = d.scratch.v2;
    v = Q;
    v.noalias() -= Phi_CB_.transpose() * SPtDtQ;
    // G is block diagonal (a 3 x 3 block per node rotation): T^T G B = sum_a T_a^T (G_a B_a)
    // with T_a, B_a node a's rotation rows.
    Eigen::MatrixXd& GB = d.scratch.n3a;
    GB.resize(3, n);
    for (int a = 0; a < n_nodes_; ++a) {
      const Eigen::Matrix3d G = LeftJacobianInverseTransposeDerivative(Eigen::Vector3d(q.segment<3>(6 * a + 3)),
                                                                       Eigen::Vector3d(v.segment<3>(6 * a + 3)));
      GB.noalias() = G * kin.B.middleRows<3>(6 * a + 3);
      Kt.noalias() += kin.T.middleRows<3>(6 * a + 3).transpose() * GB;
    }
  }
}

void SuperelementBody::ElasticForce(Data& d, Eigen::VectorXd* f, Eigen::MatrixXd* tangent,
                                    const InertiaLoadFactors* load, Eigen::MatrixXd* d_load) const {
  const int n = n_coordinates();
  const Kinematics& kin = d.kin;
  const FrameSolution& frame = d.frame;
  if (!load || K_sigma_.empty()) load = nullptr;
  const Eigen::VectorXd& Q = LocalForce(d, load);
  Eigen::VectorXd& Qhat = d.scratch.v3;  // B^T Q (T0^T Q approximated)
  Qhat.resize(n);
  if (options_.approximated) {
    Qhat.noalias() = T0_.transpose() * Q;
  } else {
    Qhat.noalias() = kin.B.transpose() * Q;
  }
  // Rbar: R_j on every node's force and moment, identity on modal rows.
  if (f) TurnBlocksInto(frame.R, Qhat, 2 * n_nodes_, *f);
  if (d_load) {
    if (load) {
      // Rbar B^T [K_sigma,k q]: node rows turned by R_j.
      d_load->resize(n, kInertiaLoadCaseCount);
      if (options_.approximated) {
        d_load->noalias() = T0_.transpose() * SigmaProducts(d);
      } else {
        d_load->noalias() = kin.B.transpose() * SigmaProducts(d);
      }
      TurnRowBlocks(*d_load, 2 * n_nodes_, [&](int) { return frame.R; });
    } else {
      d_load->setZero(n, kInertiaLoadCaseCount);
    }
  }
  if (!tangent) return;

  Eigen::MatrixXd& Kt = *tangent;  // written in place: a kept tangent's storage is reused
  const Eigen::MatrixXd* Kq = &K_;
  if (polynomial_ || (load && !K_sigma_.empty())) {
    LocalTangent(d, load, d.scratch.nn1);
    Kq = &d.scratch.nn1;
  }
  Eigen::MatrixXd& KB = d.scratch.nn2;
  KB.noalias() = *Kq * kin.B;
  Kt.resize(n, n);
  if (options_.approximated) {
    Kt.noalias() = T0_.transpose() * KB;
  } else {
    Kt.noalias() = kin.B.transpose() * KB;  // K1
  }
  if (options_.full_tangent) AddGeometricTangent(d, Q, Qhat, options_.approximated, Kt);
  // Rbar Kt Rbar^T, block by block.
  TurnNodeBlocks(Kt, 2 * n_nodes_, frame.R);
}

void SuperelementBody::InterfaceConstraint(Data& d, Eigen::VectorXd* g, Eigen::MatrixXd* G,
                                           const Eigen::VectorXd* lambda, Eigen::MatrixXd* H) const {
  const int n = n_coordinates(), r = n_constraints(), nb = 6 * n_nodes_;
  const Eigen::Matrix3d R = d.frame.R, Rt = d.frame.R.transpose();
  if (g) {
    g->resize(r);
    g->noalias() = C_ * d.q.head(nb);
  }
  if (G) {
    // d q_loc = B Rbar^T dq (exact, also with the approximated option: this is a constraint).
    G->resize(r, n);
    G->noalias() = C_ * d.kin.B.topRows(nb);
    TurnColBlocks(*G, 2 * n_nodes_, [&](int) { return Rt; });
  }
  if (!H) return;
  // G^T lambda = Rbar B^T Q with Q = C^T lambda (zero on the modal rows): the elastic force's
  // form with a local force that does not depend on the configuration, so its derivative is
  // K2 + K3 + K4 of that Q (no K1).
  Eigen::VectorXd &Q = d.scratch.v4, &Qhat = d.scratch.v3;  // (AddGeometricTangent takes v1, v2)
  Q.setZero(n);
  Q.head(nb).noalias() = C_.transpose() * *lambda;
  Qhat.resize(n);
  Qhat.noalias() = d.kin.B.transpose() * Q;
  H->setZero(n, n);
  AddGeometricTangent(d, Q, Qhat, false, *H);
  TurnNodeBlocks(*H, 2 * n_nodes_, R);
}

void SuperelementBody::InertiaForce(Data& d, const BodyVelocity& w, const BodyVelocity& wdot, Eigen::VectorXd* f_in,
                                    Eigen::MatrixXd* mass, Eigen::MatrixXd* gyroscopic, Eigen::VectorXd* f_acc) const {
  const int n = n_coordinates();
  if (has_exact_inertia()) {
    Eigen::VectorXd& zero = d.scratch.v4;
    if (!options_.quadratic_velocity_terms || (!f_in && f_acc)) zero.setZero(n);
    if (f_in) {
      ExactInertiaForce(d, options_.quadratic_velocity_terms ? w : zero, wdot, *f_in, f_acc);
    } else if (f_acc) {
      ExactInertiaForce(d, zero, wdot, *f_acc, nullptr);
    }
    if (mass) *mass = ExactMass(d);
    if (gyroscopic) {
      if (!options_.quadratic_velocity_terms) {
        gyroscopic->setZero(n, n);
        return;
      }
      ExactGyroscopic(d, w, *gyroscopic);
    }
    return;
  }
  const BodyVelocityMaps& maps = MapsOf(d);
  const Eigen::MatrixXd& U = maps.U;
  const Eigen::MatrixXd& Mg = maps.Mg;
  if (f_acc) f_acc->noalias() = Mg * wdot;
  if (f_in) {
    f_in->noalias() = Mg * wdot;
    if (options_.quadratic_velocity_terms) {
      Eigen::VectorXd& quadratic = d.scratch.v3;
      QuadraticInertia(U, Mg, w, quadratic, d.scratch);
      *f_in += quadratic;
    }
  }
  if (mass) *mass = Mg;
  if (gyroscopic) {
    if (!options_.quadratic_velocity_terms) {
      gyroscopic->setZero(n, n);
      return;
    }
    QuadraticInertiaDerivative(U, Mg, w, *gyroscopic, d.scratch);
  }
}

void SuperelementBody::InertiaConfigurationTangent(Data& d, const BodyVelocity& w, const BodyVelocity& wdot,
                                                   bool quadratic, Eigen::MatrixXd& tangent) const {
  // Exact inertia: the whole force by central differences with `quadratic`; without, the
  // corotational d(M_g wdot)/dq, which has its leading part (the turning of the frame; the exact
  // mass differs from it at the order of q_loc Omega) for a fraction of the cost.
  if (has_exact_inertia() && quadratic && options_.quadratic_velocity_terms) {
    tangent = ExactInertiaConfigurationTangent(d, w, wdot);
    return;
  }
  MomentumDerivative(MapsOf(d), wdot, tangent, d.scratch);
  if (!quadratic || !options_.quadratic_velocity_terms) return;
  const int n = n_coordinates();
  BodyScratch scratch;
  for (int i = 0; i < n; ++i) {
    Eigen::VectorXd g[2];
    double step = 1e-7;
    for (int side = 0; side < 2; ++side) {
      const BodyConfiguration p = Perturbed(d.c, i, side == 0 ? 1.0 : -1.0, &step);
      Data dp = Evaluate(p, SolveFrame(p, d.frame));
      const BodyVelocityMaps& maps = MapsOf(dp);
      QuadraticInertia(maps.U, maps.Mg, w, g[side], scratch);
    }
    tangent.col(i) += (g[0] - g[1]) / (2 * step);
  }
}

// Perturbed configuration for the central differences of the inertia force: coordinate i by
// +-step (positions 1e-7 of the body size, rotations 1e-7 rad, modal coordinates 1e-7 of the
// body size times sqrt of a mass).
BodyConfiguration SuperelementBody::Perturbed(const BodyConfiguration& c, int i, double sign, double* step) const {
  double size = 0.0;
  for (const Eigen::Vector3d& X : X_) size = std::max(size, X.norm());
  BodyConfiguration p = c;
  *step = 1e-7;
  if (i < 6 * n_nodes_) {
    const int a = i / 6, k = i % 6;
    if (k < 3) {
      *step = 1e-7 * std::max(size, 1e-3);
      p.x[a][k] += sign * *step;
    } else {
      p.R[a] = ExpSO3(sign * *step * Eigen::Vector3d::Unit(k - 3)) * p.R[a];
    }
  } else {
    *step = 1e-7 * std::max(size, 1e-3) * std::sqrt(std::max(M_(0, 0), 1e-300));
    p.eta[i - 6 * n_nodes_] += sign * *step;
  }
  return p;
}

void SuperelementBody::AddModalDamping(const BodyVelocity& w, Eigen::VectorXd& f, Eigen::MatrixXd* C) const {
  if (options_.modal_damping <= 0.0) return;
  for (int m = 0; m < n_modes_; ++m) {
    const int i = 6 * n_nodes_ + m;
    // Internal modes are mass-normalized: K_ii = omega_i^2.
    const double c = 2.0 * options_.modal_damping * std::sqrt(std::max(K_(i, i), 0.0));
    f[i] += c * w[i];
    if (C) (*C)(i, i) += c;
  }
}

void SuperelementBody::Momentum(Data& d, const BodyVelocity& w, Eigen::Vector3d* linear,
                                Eigen::Vector3d* angular) const {
  MomentumFrom(d, MassTimes(d, w), linear, angular);
}

void SuperelementBody::MomentumFrom(Data& d, const Eigen::VectorXd& p, Eigen::Vector3d* linear,
                                    Eigen::Vector3d* angular) const {
  const BodyConfiguration& c = d.c;
  linear->setZero();
  angular->setZero();
  for (int a = 0; a < n_nodes_; ++a) {
    *linear += p.segment<3>(6 * a);
    *angular += p.segment<3>(6 * a + 3) + c.x[a].cross(Eigen::Vector3d(p.segment<3>(6 * a)));
  }
}

Eigen::Vector3d SuperelementBody::CenterOfMass(const Eigen::VectorXd& q_loc, const FrameSolution& frame) const {
  Eigen::Vector3d moment;
  moment.noalias() = first_moment_map_ * q_loc;
  moment += first_moment0_;
  return frame.x + frame.R * (mass_ > 0 ? Eigen::Vector3d(moment / mass_) : Eigen::Vector3d::Zero());
}

void SuperelementBody::GravityForce(Data& data, const Eigen::Vector3d& g, Eigen::VectorXd& f) const {
  const FrameSolution& frame = data.frame;
  Eigen::VectorXd& yg = data.scratch.v1;
  const Eigen::Vector3d g_frame = frame.R.transpose() * g;
  yg.noalias() = Phi_rig0_.leftCols<3>() * g_frame;
  if (has_exact_inertia()) {
    // Virtual work of g on the field: y_g = Phi_rig0 [R_j^T g; 0] (a uniform field), delta of the
    // field = Phi (Phi_rig0 delta xi + delta q_loc) + delta theta_j x (Phi q):
    // f = Rbar (Y^T M y_g + Z_r^T H^T y_g).
    const ExactData& d = *data.exact;
    Eigen::VectorXd& Myg = data.scratch.v2;
    Myg.noalias() = M_ * yg;
    const Eigen::Vector3d Hty = d.H.transpose() * yg;
    f.noalias() = d.Y.transpose() * Myg;
    f.noalias() += data.kin.Z.bottomRows<3>().transpose() * Hty;
    TurnBlocksInto(frame.R, f, 2 * n_nodes_, f);
    return;
  }
  // P^T block by block (P is block diagonal: its 3 x 3 node blocks, then 1 on the modal rows).
  const Eigen::MatrixXd& P = MapsOf(data).P;
  f.noalias() = M_ * yg;
  for (int a = 0; a < 2 * n_nodes_; ++a)
    f.segment<3>(3 * a) = P.block<3, 3>(3 * a, 3 * a).transpose() * Eigen::Vector3d(f.segment<3>(3 * a));
}

Eigen::MatrixXd SuperelementBody::GravityTangent(Data& d, const Eigen::Vector3d& g) const {
  const int n = n_coordinates();
  if (!has_exact_inertia()) {
    // GravityForce = P^T M P wdot_g = M_g wdot_g with wdot_g = g on every node's translation rows
    // (P wdot_g = Phi_rig0 [R_j^T g; 0]): its configuration derivative is MomentumDerivative's.
    BodyVelocity wdot_g = Eigen::VectorXd::Zero(n);
    for (int a = 0; a < n_nodes_; ++a) wdot_g.segment<3>(6 * a) = g;
    Eigen::MatrixXd D;
    BodyScratch scratch;
    MomentumDerivative(MapsOf(d), wdot_g, D, scratch);
    return D;
  }
  // The exact inertia's field: central differences with the frame re-solved, as for its inertia
  // force (ExactInertiaConfigurationTangent).
  Eigen::MatrixXd tangent(n, n);
  Eigen::VectorXd f_plus, f_minus;
  for (int i = 0; i < n; ++i) {
    double step = 0.0;
    const BodyConfiguration plus = Perturbed(d.c, i, 1.0, &step), minus = Perturbed(d.c, i, -1.0, &step);
    Data at_plus = Evaluate(plus, SolveFrame(plus, d.frame)), at_minus = Evaluate(minus, SolveFrame(minus, d.frame));
    GravityForce(at_plus, g, f_plus);
    GravityForce(at_minus, g, f_minus);
    tangent.col(i) = (f_plus - f_minus) / (2 * step);
  }
  return tangent;
}

}  // namespace femb
