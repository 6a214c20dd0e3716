#include "solver/body/superelement_body.h"

#include <Eigen/Dense>
#include <limits>

#include "formats/input_error.h"
#include "solver/rotation.h"

namespace femb {
namespace {
// Local (elastic) rotations are small in this theory; beyond 2 rad a frame is rejected.
constexpr double kMaxLocalRotation = 2.0;
}  // namespace

struct SuperelementBody::Kinematics {
  Eigen::MatrixXd Phi_rig;  // n x 6
  Eigen::MatrixXd D;        // n x n (block diagonal)
  Eigen::Matrix<double, 6, 6> S;
  Eigen::MatrixXd Z;        // 6 x n
  Eigen::MatrixXd T;        // n x n
  Eigen::MatrixXd B;        // n x n
};

SuperelementBody::SuperelementBody(const Superelement& se, const SuperelementOptions& options,
                                   const Eigen::Matrix3d& placement_R, const Eigen::Vector3d& placement_x)
    : n_nodes_(se.n_interface_nodes()),
      n_modes_(se.n_reduced_dofs() - se.n_interface_dofs()),
      options_(options),
      K_(se.K),
      M_(se.M),
      Phi_CB_(se.floating_frame.Phi_CB),
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
  force_floor_ = 1e-4 * k_max_ * length;
  // A file's polynomial is the modal derivatives' cubic force (option polynomial_force) or,
  // without derivatives, the geometric stiffening's quadratic force (option geometric_stiffening).
  if (se.polynomial && (se.polynomial->cubic() ? options_.polynomial_force : options_.geometric_stiffening)) {
    polynomial_ = se.polynomial;
  }
  if (options_.geometric_stiffening) K_sigma_ = se.inertia_stiffness;
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

Eigen::VectorXd SuperelementBody::LocalCoordinates(const BodyConfiguration& c, const FrameSolution& frame) const {
  Eigen::VectorXd q(n_coordinates());
  const Eigen::Matrix3d Rt = frame.R.transpose();
  for (int k = 0; k < n_nodes_; ++k) {
    q.segment<3>(6 * k) = Rt * (c.x[k] - frame.x) - X_[k];
    q.segment<3>(6 * k + 3) = LogSO3(Rt * c.R[k] * R0_[k].transpose());
  }
  q.tail(n_modes_) = c.eta;
  return q;
}

SuperelementBody::Kinematics SuperelementBody::ComputeKinematics(const Eigen::VectorXd& q) const {
  const int n = n_coordinates();
  Kinematics k;
  k.Phi_rig = Eigen::MatrixXd::Zero(n, 6);
  k.D = Eigen::MatrixXd::Identity(n, n);
  for (int a = 0; a < n_nodes_; ++a) {
    const Eigen::Vector3d r = X_[a] + q.segment<3>(6 * a);
    auto block = k.Phi_rig.block<6, 6>(6 * a, 0);
    block.setIdentity();
    block.block<3, 3>(0, 3) = -Skew<double>(r);
    k.D.block<3, 3>(6 * a + 3, 6 * a + 3) = LeftJacobianInverse<double>(Eigen::Vector3d(q.segment<3>(6 * a + 3)));
  }
  const Eigen::MatrixXd W = Phi_CB_ * k.D;
  k.S = W * k.Phi_rig;
  k.Z = k.S.lu().solve(W);
  k.T = Eigen::MatrixXd::Identity(n, n) - k.Phi_rig * k.Z;
  k.B = k.D * k.T;
  return k;
}

FrameSolution SuperelementBody::GuessFrame(const BodyConfiguration& c) const {
  FrameSolution frame;
  frame.R = c.R[0] * R0_[0].transpose();
  frame.x = c.x[0] - frame.R * X_[0];
  return frame;
}

double SuperelementBody::RoundOffForce(const BodyConfiguration& c) const {
  double x = 0.0;
  for (const Eigen::Vector3d& xk : c.x) x = std::max(x, xk.norm());
  return 16.0 * std::sqrt(double(n_coordinates())) * std::numeric_limits<double>::epsilon() * k_max_ * x;
}

FrameSolution SuperelementBody::SolveFrame(const BodyConfiguration& c, const FrameSolution& guess) const {
  FrameSolution frame = guess;
  frame.ok = false;
  // Translations relative to the body size, plus the round-off of the absolute positions (a
  // body 1e4 m from the origin knows its node positions to 2e-12 m only); rotations as they are.
  double size = 0.0, far = 0.0;
  for (int k = 0; k < n_nodes_; ++k) size = std::max(size, X_[k].norm());
  for (const Eigen::Vector3d& x : c.x) far = std::max(far, x.norm());
  const double tolerance = 1e-13 * size + 32 * std::numeric_limits<double>::epsilon() * far;
  for (int it = 0; it < 30; ++it) {
    const Eigen::VectorXd q = LocalCoordinates(c, frame);
    Eigen::Matrix<double, 6, 1> g = Phi_CB_ * q;
    frame.iterations = it;
    if (g.head<3>().norm() <= std::max(tolerance, 1e-300) && g.tail<3>().norm() <= 1e-13) {
      // A root with local rotations beyond kMaxLocalRotation is a spurious branch of the log
      // map (far start), not an elastic state: report failure.
      frame.ok = true;
      for (int k = 0; k < n_nodes_; ++k) frame.ok &= q.segment<3>(6 * k + 3).norm() < kMaxLocalRotation;
      return frame;
    }
    // d q_loc = -D Phi_rig zeta for a frame variation zeta (frame axes): zeta = S^-1 g.
    const Kinematics kin = ComputeKinematics(q);
    const Eigen::Matrix<double, 6, 1> zeta = kin.S.lu().solve(g);
    frame.x += frame.R * zeta.head<3>();
    frame.R = frame.R * ExpSO3(zeta.tail<3>());
  }
  return frame;
}

Eigen::VectorXd SuperelementBody::LocalForce(const Eigen::VectorXd& q, const InertiaLoadFactors* load) const {
  Eigen::VectorXd f = polynomial_ ? PolynomialForce(K_, *polynomial_, q) : Eigen::VectorXd(K_ * q);
  if (load && !K_sigma_.empty()) {
    for (int k = 0; k < kInertiaLoadCaseCount; ++k)
      if (load->a[k] != 0.0) f.noalias() += load->a[k] * (K_sigma_[size_t(k)] * q);
  }
  return f;
}

Eigen::MatrixXd SuperelementBody::LocalTangent(const Eigen::VectorXd& q, const InertiaLoadFactors* load) const {
  Eigen::MatrixXd K = polynomial_ ? PolynomialTangent(K_, *polynomial_, q) : K_;
  if (load && !K_sigma_.empty()) {
    for (int k = 0; k < kInertiaLoadCaseCount; ++k)
      if (load->a[k] != 0.0) K += load->a[k] * K_sigma_[size_t(k)];
  }
  return K;
}

InertiaLoadFactors SuperelementBody::InertiaLoads(const BodyConfiguration& c, const FrameSolution& frame,
                                                   const BodyVelocity& w, const BodyVelocity& wdot,
                                                   const Eigen::Vector3d& gravity) const {
  const int n = n_coordinates();
  InertiaLoadFactors out;
  out.d_w = Eigen::MatrixXd::Zero(12, n);
  out.d_wdot = Eigen::MatrixXd::Zero(12, n);
  const Eigen::VectorXd q = LocalCoordinates(c, frame);
  const Kinematics kin = ComputeKinematics(q);
  // Z Rbar^T: node vectors to frame axes, then the frame's part.
  Eigen::MatrixXd ZR = kin.Z;
  for (int a = 0; a < 2 * n_nodes_; ++a) ZR.middleCols<3>(3 * a) = kin.Z.middleCols<3>(3 * a) * frame.R.transpose();
  const Eigen::Vector3d omega = ZR.bottomRows<3>() * w;
  const Eigen::MatrixXd d_omega = ZR.bottomRows<3>();  // 3 x n
  // Node accelerations in frame axes minus the centrifugal part of the rigid motion.
  Eigen::Matrix<double, 6, 1> acc = ZR * wdot;
  Eigen::Matrix<double, 6, 3> d_acc_d_omega = Eigen::Matrix<double, 6, 3>::Zero();
  for (int a = 0; a < n_nodes_; ++a) {
    const Eigen::Vector3d r = X_[a] + q.segment<3>(6 * a);
    const Eigen::Vector3d centrifugal = omega * omega.dot(r) - omega.squaredNorm() * r;
    // d/d omega [omega (omega . r) - |omega|^2 r] = (omega . r) 1 + omega r^T - 2 r omega^T.
    const Eigen::Matrix3d d_centrifugal =
        omega.dot(r) * Eigen::Matrix3d::Identity() + omega * r.transpose() - 2.0 * r * omega.transpose();
    acc -= kin.Z.middleCols<3>(6 * a) * centrifugal;
    d_acc_d_omega -= kin.Z.middleCols<3>(6 * a) * d_centrifugal;
  }
  out.a.head<3>() = acc.head<3>() - frame.R.transpose() * gravity;
  out.a.segment<3>(3) = acc.tail<3>();
  out.a.tail<6>() << omega.x() * omega.x(), omega.y() * omega.y(), omega.z() * omega.z(), omega.x() * omega.y(),
      omega.x() * omega.z(), omega.y() * omega.z();
  out.d_wdot.topRows<6>() = ZR;
  Eigen::Matrix<double, 6, 3> d_products;
  d_products << 2 * omega.x(), 0, 0, 0, 2 * omega.y(), 0, 0, 0, 2 * omega.z(), omega.y(), omega.x(), 0, omega.z(), 0,
      omega.x(), 0, omega.z(), omega.y();
  out.d_w.topRows<6>() = d_acc_d_omega * d_omega;
  out.d_w.bottomRows<6>() = d_products * d_omega;
  return out;
}

double SuperelementBody::ElasticEnergy(const BodyConfiguration& c, const FrameSolution& frame) const {
  const Eigen::VectorXd q = LocalCoordinates(c, frame);
  return polynomial_ ? PolynomialEnergy(K_, *polynomial_, q) : 0.5 * q.dot(K_ * q);
}

void SuperelementBody::ElasticForce(const BodyConfiguration& c, const FrameSolution& frame, Eigen::VectorXd* f,
                                    Eigen::MatrixXd* tangent, const InertiaLoadFactors* load,
                                    Eigen::MatrixXd* d_load) const {
  const int n = n_coordinates();
  const Eigen::VectorXd q = LocalCoordinates(c, frame);
  const Kinematics kin = ComputeKinematics(q);
  if (!load || K_sigma_.empty()) load = nullptr;
  const Eigen::VectorXd Q = LocalForce(q, load);
  const Eigen::VectorXd Qhat = options_.approximated ? Eigen::VectorXd(T0_.transpose() * Q)
                                                     : Eigen::VectorXd(kin.B.transpose() * Q);
  // Rbar: R_j on every node's force and moment, identity on modal rows.
  auto rotate = [&](const Eigen::VectorXd& local) {
    Eigen::VectorXd global = local;
    for (int a = 0; a < 2 * n_nodes_; ++a) global.segment<3>(3 * a) = frame.R * local.segment<3>(3 * a);
    return global;
  };
  if (f) *f = rotate(Qhat);
  if (d_load) {
    d_load->setZero(n, kInertiaLoadCaseCount);
    for (int k = 0; load && k < kInertiaLoadCaseCount; ++k) {
      const Eigen::VectorXd Kq_k = K_sigma_[size_t(k)] * q;
      d_load->col(k) = rotate(options_.approximated ? Eigen::VectorXd(T0_.transpose() * Kq_k)
                                                    : Eigen::VectorXd(kin.B.transpose() * Kq_k));
    }
  }
  if (!tangent) return;

  Eigen::MatrixXd Kt;
  const Eigen::MatrixXd Kq = LocalTangent(q, load);
  if (options_.approximated) {
    Kt = T0_.transpose() * Kq * kin.B;
  } else {
    Kt = kin.B.transpose() * Kq * kin.B;  // K1
  }
  if (options_.full_tangent) {
    // Fhat, Mhat (n x 6) from Qhat: node rows [0, F~; 0, 0] and [0, 0; 0, M~].
    Eigen::MatrixXd Fhat = Eigen::MatrixXd::Zero(n, 6), FMhat = Eigen::MatrixXd::Zero(n, 6);
    for (int a = 0; a < n_nodes_; ++a) {
      const Eigen::Matrix3d F = Skew<double>(Eigen::Vector3d(Qhat.segment<3>(6 * a)));
      Fhat.block<3, 3>(6 * a, 3) = F;
      FMhat.block<3, 3>(6 * a, 3) = F;
      FMhat.block<3, 3>(6 * a + 3, 3) = Skew<double>(Eigen::Vector3d(Qhat.segment<3>(6 * a + 3)));
    }
    Kt -= FMhat * kin.Z;  // K3: rotation of the frame
    if (!options_.approximated) {
      Kt -= kin.Z.transpose() * Fhat.transpose() * kin.B;  // K2: variation of Phi_rig in T
      // K4: variation of D (exact rotation kinematics), v = P^T Q, P = 1 - D Phi_rig S^-1 Phi_CB.
      const Eigen::VectorXd v =
          Q - Phi_CB_.transpose() * kin.S.transpose().lu().solve(kin.Phi_rig.transpose() * (kin.D.transpose() * Q));
      Eigen::MatrixXd G = Eigen::MatrixXd::Zero(n, n);
      for (int a = 0; a < n_nodes_; ++a) {
        G.block<3, 3>(6 * a + 3, 6 * a + 3) = LeftJacobianInverseTransposeDerivative(
            Eigen::Vector3d(q.segment<3>(6 * a + 3)), Eigen::Vector3d(v.segment<3>(6 * a + 3)));
      }
      Kt += kin.T.transpose() * G * kin.B;
    }
  }
  // Rbar Kt Rbar^T.
  Eigen::MatrixXd Rbar = Eigen::MatrixXd::Identity(n, n);
  for (int a = 0; a < 2 * n_nodes_; ++a) Rbar.block<3, 3>(3 * a, 3 * a) = frame.R;
  *tangent = Rbar * Kt * Rbar.transpose();
}

void SuperelementBody::VelocityMaps(const BodyConfiguration& c, const FrameSolution& frame, Eigen::MatrixXd* P,
                                    Eigen::MatrixXd* U) const {
  const int n = n_coordinates();
  const Eigen::VectorXd q = LocalCoordinates(c, frame);
  const Kinematics kin = ComputeKinematics(q);
  Eigen::MatrixXd Rbar_t = Eigen::MatrixXd::Identity(n, n);
  *P = Eigen::MatrixXd::Identity(n, n);
  for (int a = 0; a < n_nodes_; ++a) {
    Rbar_t.block<3, 3>(6 * a, 6 * a) = frame.R.transpose();
    Rbar_t.block<3, 3>(6 * a + 3, 6 * a + 3) = frame.R.transpose();
    P->block<3, 3>(6 * a, 6 * a) = frame.R.transpose();
    P->block<3, 3>(6 * a + 3, 6 * a + 3) = options_.cardona_option_b ? c.R[a].transpose() : frame.R.transpose();
  }
  // Spatial variation of the frame rotation: d pi_j = R_j (Z Rbar^T dq)_rot (thesis 3.17).
  *U = frame.R * (kin.Z * Rbar_t).bottomRows(3);
}

Eigen::MatrixXd SuperelementBody::VelocityMapRate(const Eigen::MatrixXd& U, const BodyVelocity& w) const {
  const int n = n_coordinates();
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(n, n);
  for (int a = 0; a < n_nodes_; ++a) {
    const Eigen::Vector3d xdot = w.segment<3>(6 * a), omega = w.segment<3>(6 * a + 3);
    G.middleRows<3>(6 * a) = Skew<double>(xdot) * U;
    if (options_.cardona_option_b) {
      G.block<3, 3>(6 * a + 3, 6 * a + 3) = Skew<double>(omega);
    } else {
      G.middleRows<3>(6 * a + 3) = Skew<double>(omega) * U;
    }
  }
  return G;
}

Eigen::VectorXd SuperelementBody::QuadraticInertia(const Eigen::MatrixXd& U, const Eigen::MatrixXd& Mg,
                                                   const BodyVelocity& w) const {
  const Eigen::Vector3d omega_j = U * w;
  const Eigen::MatrixXd G = VelocityMapRate(U, w);
  const Eigen::VectorXd p = Mg * w;
  Eigen::VectorXd out = Mg * (G * w) - G.transpose() * p;
  for (int a = 0; a < n_nodes_; ++a) {
    const Eigen::Vector3d omega = w.segment<3>(6 * a + 3);
    // (Omega_P - Omega_hat) p: translation rows omega_j~, rotation rows omega_j~ - omega_a~ (A), 0 (B).
    out.segment<3>(6 * a) += omega_j.cross(Eigen::Vector3d(p.segment<3>(6 * a)));
    if (!options_.cardona_option_b) {
      out.segment<3>(6 * a + 3) += (omega_j - omega).cross(Eigen::Vector3d(p.segment<3>(6 * a + 3)));
    }
  }
  return out;
}

void SuperelementBody::InertiaForce(const BodyConfiguration& c, const FrameSolution& frame, const BodyVelocity& w,
                                    const BodyVelocity& wdot, Eigen::VectorXd* f_in, Eigen::MatrixXd* mass,
                                    Eigen::MatrixXd* gyroscopic) const {
  const int n = n_coordinates();
  Eigen::MatrixXd P, U;
  VelocityMaps(c, frame, &P, &U);
  const Eigen::MatrixXd Mg = P.transpose() * M_ * P;
  if (f_in) {
    *f_in = Mg * wdot;
    if (options_.quadratic_velocity_terms) *f_in += QuadraticInertia(U, Mg, w);
  }
  if (mass) *mass = Mg;
  if (gyroscopic) {
    gyroscopic->setZero(n, n);
    if (!options_.quadratic_velocity_terms) return;
    // g(w) is quadratic: Dg(w) e = [g(w + s e) - g(w) - g(s e)] / s exactly, for any s > 0.
    const double s = std::max(w.norm(), 1.0);
    const Eigen::VectorXd g0 = QuadraticInertia(U, Mg, w);
    for (int i = 0; i < n; ++i) {
      const Eigen::VectorXd e = s * Eigen::VectorXd::Unit(n, i);
      gyroscopic->col(i) = (QuadraticInertia(U, Mg, w + e) - g0 - QuadraticInertia(U, Mg, e)) / s;
    }
  }
}

Eigen::MatrixXd SuperelementBody::InertiaConfigurationTangent(const BodyConfiguration& c, const FrameSolution& frame,
                                                              const BodyVelocity& w, const BodyVelocity& wdot,
                                                              bool quadratic) const {
  Eigen::MatrixXd tangent = MomentumDerivative(Maps(c, frame), wdot);
  if (!quadratic || !options_.quadratic_velocity_terms) return tangent;
  double size = 0.0;
  for (const Eigen::Vector3d& X : X_) size = std::max(size, X.norm());
  const int n = n_coordinates();
  for (int i = 0; i < n; ++i) {
    Eigen::VectorXd g[2];
    double step = 1e-7;
    for (int side = 0; side < 2; ++side) {
      BodyConfiguration p = c;
      const double e = side == 0 ? 1.0 : -1.0;
      if (i < 6 * n_nodes_) {
        const int a = i / 6, k = i % 6;
        if (k < 3) {
          step = 1e-7 * std::max(size, 1e-3);
          p.x[a][k] += e * step;
        } else {
          p.R[a] = ExpSO3(e * step * Eigen::Vector3d::Unit(k - 3)) * p.R[a];
        }
      } else {
        // Mass-normalized modal coordinates: scale by the body's mass (eta ~ sqrt(m) x length).
        step = 1e-7 * std::max(size, 1e-3) * std::sqrt(std::max(M_(0, 0), 1e-300));
        p.eta[i - 6 * n_nodes_] += e * step;
      }
      Eigen::MatrixXd P, U;
      VelocityMaps(p, SolveFrame(p, frame), &P, &U);
      g[side] = QuadraticInertia(U, P.transpose() * M_ * P, w);
    }
    tangent.col(i) += (g[0] - g[1]) / (2 * step);
  }
  return tangent;
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

double SuperelementBody::KineticEnergy(const BodyConfiguration& c, const FrameSolution& frame,
                                       const BodyVelocity& w) const {
  Eigen::MatrixXd P, U;
  VelocityMaps(c, frame, &P, &U);
  const Eigen::VectorXd v = P * w;
  return 0.5 * v.dot(M_ * v);
}

BodyVelocityMaps SuperelementBody::Maps(const BodyConfiguration& c, const FrameSolution& frame) const {
  BodyVelocityMaps maps;
  VelocityMaps(c, frame, &maps.P, &maps.U);
  maps.Mg = maps.P.transpose() * M_ * maps.P;
  return maps;
}

Eigen::VectorXd SuperelementBody::GeneralizedMomentum(const BodyVelocityMaps& maps, const BodyVelocity& w) const {
  return maps.Mg * w;
}

Eigen::MatrixXd SuperelementBody::MomentumDerivative(const BodyVelocityMaps& maps, const BodyVelocity& w) const {
  const Eigen::MatrixXd& U = maps.U;
  const Eigen::VectorXd p = maps.Mg * w;
  // dp = dP^T mu + M_g G dq, mu = M P w; P^T turns each node block with R_j (or R_k).
  Eigen::MatrixXd D = maps.Mg * VelocityMapRate(U, w);
  for (int a = 0; a < n_nodes_; ++a) {
    D.middleRows<3>(6 * a) -= Skew<double>(Eigen::Vector3d(p.segment<3>(6 * a))) * U;
    const Eigen::Matrix3d p_rot = Skew<double>(Eigen::Vector3d(p.segment<3>(6 * a + 3)));
    if (options_.cardona_option_b) {
      D.block<3, 3>(6 * a + 3, 6 * a + 3) -= p_rot;
    } else {
      D.middleRows<3>(6 * a + 3) -= p_rot * U;
    }
  }
  return D;
}

void SuperelementBody::MomentumSourceDerivatives(const BodyVelocityMaps& maps, const BodyVelocity& w,
                                                 const Eigen::VectorXd& p, Eigen::MatrixXd* d_w,
                                                 Eigen::MatrixXd* d_p) const {
  const int n = n_coordinates();
  const Eigen::MatrixXd& U = maps.U;
  // s = G(w)^T p + Omega_hat(w) p is bilinear in (w, p).
  *d_p = VelocityMapRate(U, w).transpose();
  d_w->setZero(n, n);
  for (int a = 0; a < n_nodes_; ++a) {
    const Eigen::Vector3d omega = w.segment<3>(6 * a + 3);
    d_p->block<3, 3>(6 * a + 3, 6 * a + 3) += Skew<double>(omega);
    // G(e)^T p = U^T (p_x~ e_x + p_pi~ e_pi) (option A); Omega_hat(e) p = -p_pi~ e_pi.
    const Eigen::Matrix3d px = Skew<double>(Eigen::Vector3d(p.segment<3>(6 * a)));
    const Eigen::Matrix3d pr = Skew<double>(Eigen::Vector3d(p.segment<3>(6 * a + 3)));
    d_w->middleCols<3>(6 * a) += U.transpose() * px;
    if (!options_.cardona_option_b) {
      d_w->middleCols<3>(6 * a + 3) += U.transpose() * pr;
      d_w->block<3, 3>(6 * a + 3, 6 * a + 3) -= pr;
    }
    // Option B: the node's own G block (p_pi~ e) and Omega_hat(e) p (-p_pi~ e) cancel.
  }
}

Eigen::VectorXd SuperelementBody::MomentumSource(const BodyVelocityMaps& maps, const BodyVelocity& w,
                                                 const Eigen::VectorXd& p) const {
  Eigen::VectorXd out = VelocityMapRate(maps.U, w).transpose() * p;
  for (int a = 0; a < n_nodes_; ++a) {
    out.segment<3>(6 * a + 3) += Eigen::Vector3d(w.segment<3>(6 * a + 3)).cross(Eigen::Vector3d(p.segment<3>(6 * a + 3)));
  }
  return out;
}

void SuperelementBody::Momentum(const BodyConfiguration& c, const FrameSolution& frame, const BodyVelocity& w,
                                Eigen::Vector3d* linear, Eigen::Vector3d* angular) const {
  const Eigen::VectorXd p = GeneralizedMomentum(Maps(c, frame), w);
  linear->setZero();
  angular->setZero();
  for (int a = 0; a < n_nodes_; ++a) {
    *linear += p.segment<3>(6 * a);
    *angular += p.segment<3>(6 * a + 3) + c.x[a].cross(Eigen::Vector3d(p.segment<3>(6 * a)));
  }
}

Eigen::VectorXd SuperelementBody::GravityForce(const BodyConfiguration& c, const FrameSolution& frame,
                                               const Eigen::Vector3d& g) const {
  Eigen::MatrixXd P, U;
  VelocityMaps(c, frame, &P, &U);
  Eigen::Matrix<double, 6, 1> rigid;
  rigid << frame.R.transpose() * g, Eigen::Vector3d::Zero();
  return P.transpose() * (M_ * (Phi_rig0_ * rigid));
}

}  // namespace femb
