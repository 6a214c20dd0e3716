// The floating frame: its Newton solve, the local coordinates, the kinematic maps of one
// configuration (thesis 3.14-3.18 with the exact rotation kinematics D), the frame's motion.
#include "solver/body/floating_frame.h"

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

namespace {
// Local (elastic) rotations are small in this theory; beyond 2 rad a frame is rejected.
constexpr double kMaxLocalRotation = 2.0;
}  // namespace

BodyConfiguration InitialConfiguration(const SuperelementBody& body) {
  BodyConfiguration c;
  for (int k = 0; k < body.n_nodes_; ++k) {
    c.x.push_back(body.placement_x_ + body.placement_R_ * (body.origin_part_ + body.X_[k]));
    c.R.push_back(body.placement_R_ * body.R0_[k]);
  }
  c.eta = Eigen::VectorXd::Zero(body.n_modes_);
  return c;
}

void LocalCoordinates(const SuperelementBody& body, const BodyConfiguration& c, const FrameSolution& frame,
                      Eigen::VectorXd& q) {
  q.resize(body.n_coordinates());
  const Eigen::Matrix3d Rt = frame.R.transpose();
  for (int k = 0; k < body.n_nodes_; ++k) {
    q.segment<3>(6 * k) = Rt * (c.x[k] - frame.x) - body.X_[k];
    q.segment<3>(6 * k + 3) = LogSO3(Eigen::Matrix3d(Rt * c.R[k] * body.R0_[k].transpose()));
  }
  q.tail(body.n_modes_) = c.eta;
}

Eigen::Matrix<double, 6, 6> FrameMatrix(const SuperelementBody& body, const Eigen::VectorXd& q) {
  // S = Phi_CB D Phi_rig node by node: node a's rows of D Phi_rig are [1, -r_a~] (translations)
  // and [0, J_l^-1(theta_a)] (rotations); the modal rows are zero.
  Eigen::Matrix<double, 6, 6> S = Eigen::Matrix<double, 6, 6>::Zero();
  for (int a = 0; a < body.n_nodes_; ++a) {
    const Eigen::Vector3d r = body.X_[a] + q.segment<3>(6 * a);
    const Eigen::Matrix<double, 6, 3> Pt = body.Phi_CB_.middleCols<3>(6 * a),
                                      Pr = body.Phi_CB_.middleCols<3>(6 * a + 3);
    S.leftCols<3>() += Pt;
    S.rightCols<3>() +=
        Pr * LeftJacobianInverse<double>(Eigen::Vector3d(q.segment<3>(6 * a + 3))) - Pt * Skew<double>(r);
  }
  return S;
}

FrameSolution GuessFrame(const SuperelementBody& body, const BodyConfiguration& c) {
  FrameSolution frame;
  frame.R = c.R[0] * body.R0_[0].transpose();
  frame.x = c.x[0] - frame.R * body.X_[0];
  return frame;
}

FrameSolution SolveFrameFrom(const SuperelementBody& body, const BodyConfiguration& c, const FrameSolution& last,
                             Eigen::VectorXd* q_scratch, const Eigen::Matrix<double, 6, 6>* S_inv) {
  Eigen::VectorXd own;
  Eigen::VectorXd& q = q_scratch ? *q_scratch : own;
  FrameSolution frame = SolveFrame(body, c, last, &q, S_inv);
  if (!frame.ok && S_inv) frame = SolveFrame(body, c, last, &q);
  return frame.ok ? frame : SolveFrame(body, c, GuessFrame(body, c), &q);
}

FrameSolution SolveFrame(const SuperelementBody& body, const BodyConfiguration& c, const FrameSolution& guess,
                         Eigen::VectorXd* q_scratch, const Eigen::Matrix<double, 6, 6>* S_inv) {
  Eigen::VectorXd own;
  Eigen::VectorXd& q = q_scratch ? *q_scratch : own;
  FrameSolution frame = guess;
  frame.ok = false;
  // Translations relative to the body size, plus the round-off of the absolute positions (a
  // body 1e4 m from the origin knows its node positions to 2e-12 m only); rotations as they are.
  double size = 0.0, far = 0.0;
  for (int k = 0; k < body.n_nodes_; ++k) size = std::max(size, body.X_[k].norm());
  for (const Eigen::Vector3d& x : c.x) far = std::max(far, x.norm());
  const double tolerance = 1e-13 * size + 32 * std::numeric_limits<double>::epsilon() * far;
  for (int it = 0; it < 30; ++it) {
    LocalCoordinates(body, c, frame, q);
    Eigen::Matrix<double, 6, 1> g;
    g.noalias() = body.Phi_CB_ * q;
    frame.iterations = it;
    if (g.head<3>().norm() <= std::max(tolerance, 1e-300) && g.tail<3>().norm() <= 1e-13) {
      // A root with local rotations beyond kMaxLocalRotation is a spurious branch of the log
      // map (far start), not an elastic state: report failure.
      frame.ok = true;
      for (int k = 0; k < body.n_nodes_; ++k) frame.ok &= q.segment<3>(6 * k + 3).norm() < kMaxLocalRotation;
      return frame;
    }
    // d q_loc = -D Phi_rig zeta for a frame variation zeta (frame axes): zeta = S^-1 g (with
    // the given S^-1: a chord iteration).
    const Eigen::Matrix<double, 6, 1> zeta = S_inv ? (*S_inv * g).eval() : FrameMatrix(body, q).lu().solve(g);
    frame.x += frame.R * zeta.head<3>();
    frame.R = frame.R * ExpSO3(zeta.tail<3>());
  }
  return frame;
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

void ComputeKinematics(const SuperelementBody& body, const Eigen::VectorXd& q, BodyKinematics& k) {
  const int n = body.n_coordinates();
  k.Phi_rig.setZero(n, 6);
  // D is block diagonal and Phi_rig is a [1, -r_a~; 0, 1] block per node: every product below
  // goes node block by node block (O(n) per block, no n^3 or dense n x n products).
  std::vector<Eigen::Matrix3d>& Jinv = k.Jinv;
  Jinv.resize(static_cast<size_t>(body.n_nodes_));
  Eigen::MatrixXd& W = k.W;
  W = body.Phi_CB_;  // Phi_CB D
  k.S.setZero();
  for (int a = 0; a < body.n_nodes_; ++a) {
    const Eigen::Matrix3d r_skew = Skew<double>(Eigen::Vector3d(body.X_[a] + q.segment<3>(6 * a)));
    auto block = k.Phi_rig.block<6, 6>(6 * a, 0);
    block.setIdentity();
    block.block<3, 3>(0, 3) = -r_skew;
    Jinv[size_t(a)] = LeftJacobianInverse<double>(Eigen::Vector3d(q.segment<3>(6 * a + 3)));
    W.middleCols<3>(6 * a + 3).noalias() = body.Phi_CB_.middleCols<3>(6 * a + 3) * Jinv[size_t(a)];
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
  for (int a = 0; a < body.n_nodes_; ++a) {
    const Eigen::Matrix3d r_skew = Skew<double>(Eigen::Vector3d(body.X_[a] + q.segment<3>(6 * a)));
    k.T.middleRows<3>(6 * a) -= Zt;
    k.T.middleRows<3>(6 * a).noalias() += r_skew * Zr;
    k.T.middleRows<3>(6 * a + 3) -= Zr;
  }
  k.B = k.T;
  for (int a = 0; a < body.n_nodes_; ++a)
    k.B.middleRows<3>(6 * a + 3).noalias() = Jinv[size_t(a)] * k.T.middleRows<3>(6 * a + 3);
}

BodyData Evaluate(const SuperelementBody& body, const BodyConfiguration& c, const FrameSolution& frame) {
  BodyData d;
  Evaluate(body, c, frame, d);
  return d;
}

void Evaluate(const SuperelementBody& body, const BodyConfiguration& c, const FrameSolution& frame, BodyData& d) {
  LocalCoordinates(body, c, frame, d.q);
  EvaluateSolved(body, c, frame, d);
}

FrameSolution PlaceBody(const SuperelementBody& body, const FrameSolution& last, BodyData& d, bool warm) {
  const bool kinematics = warm && d.kin.W.cols() == body.n_coordinates();
  const FrameSolution frame = SolveFrameFrom(body, d.c, last, &d.q, kinematics ? &d.kin.S_inv : nullptr);
  if (frame.ok) EvaluateSolved(body, d.c, frame, d);
  return frame;
}

void EvaluateSolved(const SuperelementBody& body, const BodyConfiguration& c, const FrameSolution& frame, BodyData& d) {
  if (&c != &d.c) d.c = c;
  d.frame = frame;
  ComputeKinematics(body, d.q, d.kin);
  if (body.has_exact_inertia()) {
    if (!d.exact) d.exact.emplace();
    Exact(body, d.q, d.kin, *d.exact);
  } else {
    d.exact.reset();
  }
  d.has_maps = false;
  d.local_force.valid = false;
  d.has_exact_mass = false;
  d.has_sigma_q = false;
  d.has_eps = false;
}

LocalMotion LocalRates(const SuperelementBody& body, BodyData& data, const BodyVelocity& w, const BodyVelocity* wdot) {
  const int blocks = 2 * body.n_nodes_;
  const Eigen::Matrix3d Rt = data.frame.R.transpose();
  Eigen::VectorXd Rw;
  TurnBlocksInto(Rt, w, blocks, Rw);
  LocalMotion out;
  const Eigen::Matrix<double, 6, 1> xi = data.kin.Z * Rw;
  out.V = xi.head<3>();
  out.Omega = xi.tail<3>();
  out.qdot = data.kin.B * Rw;
  out.qddot.setZero(out.qdot.size());
  if (wdot) {
    Eigen::VectorXd r;
    TurnBlocksInto(Rt, *wdot, blocks, r);
    SubtractRateTerms(body, data.q, out.Omega, Rw, out.qdot, r);
    const Eigen::Matrix<double, 6, 1> xidot = data.kin.Z * r;
    out.Vdot = xidot.head<3>();
    out.Omegadot = xidot.tail<3>();
    out.qddot = data.kin.B * r;
  }
  return out;
}

Eigen::Vector3d CenterOfMass(const SuperelementBody& body, const Eigen::VectorXd& q_loc, const FrameSolution& frame) {
  Eigen::Vector3d moment;
  moment.noalias() = body.first_moment_map_ * q_loc;
  moment += body.first_moment0_;
  return frame.x + frame.R * (body.mass_ > 0 ? Eigen::Vector3d(moment / body.mass_) : Eigen::Vector3d::Zero());
}

// Perturbed configuration for the central differences of the inertia force: coordinate i by
// +-step (positions 1e-7 of the body size, rotations 1e-7 rad, modal coordinates 1e-7 of the
// body size times sqrt of a mass).
BodyConfiguration Perturbed(const SuperelementBody& body, const BodyConfiguration& c, int i, double sign,
                            double* step) {
  double size = 0.0;
  for (const Eigen::Vector3d& X : body.X_) size = std::max(size, X.norm());
  BodyConfiguration p = c;
  *step = 1e-7;
  if (i < 6 * body.n_nodes_) {
    const int a = i / 6, k = i % 6;
    if (k < 3) {
      *step = 1e-7 * std::max(size, 1e-3);
      p.x[a][k] += sign * *step;
    } else {
      p.R[a] = ExpSO3(sign * *step * Eigen::Vector3d::Unit(k - 3)) * p.R[a];
    }
  } else {
    *step = 1e-7 * std::max(size, 1e-3) * std::sqrt(std::max(body.M_(0, 0), 1e-300));
    p.eta[i - 6 * body.n_nodes_] += sign * *step;
  }
  return p;
}

}  // namespace femb
