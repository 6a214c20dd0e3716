// The floating frame of a superelement (thesis 3.1-3.7, 4.2): the local coordinates of a
// configuration in a frame, the frame matrix S = Phi_CB D Phi_rig, and the Newton solution of
// Phi_CB q_loc(x_j, R_j) = 0 for the frame.
#include <Eigen/Dense>
#include <limits>

#include "solver/body/superelement_body.h"
#include "solver/rotation.h"

namespace femb {
namespace {
// Local (elastic) rotations are small in this theory; beyond 2 rad a frame is rejected.
constexpr double kMaxLocalRotation = 2.0;
}  // namespace

void SuperelementBody::LocalCoordinates(const BodyConfiguration& c, const FrameSolution& frame,
                                        Eigen::VectorXd& q) const {
  q.resize(n_coordinates());
  const Eigen::Matrix3d Rt = frame.R.transpose();
  for (int k = 0; k < n_nodes_; ++k) {
    q.segment<3>(6 * k) = Rt * (c.x[k] - frame.x) - X_[k];
    q.segment<3>(6 * k + 3) = LogSO3(Eigen::Matrix3d(Rt * c.R[k] * R0_[k].transpose()));
  }
  q.tail(n_modes_) = c.eta;
}

Eigen::Matrix<double, 6, 6> SuperelementBody::FrameMatrix(const Eigen::VectorXd& q) const {
  // S = Phi_CB D Phi_rig node by node: node a's rows of D Phi_rig are [1, -r_a~] (translations)
  // and [0, J_l^-1(theta_a)] (rotations); the modal rows are zero.
  Eigen::Matrix<double, 6, 6> S = Eigen::Matrix<double, 6, 6>::Zero();
  for (int a = 0; a < n_nodes_; ++a) {
    const Eigen::Vector3d r = X_[a] + q.segment<3>(6 * a);
    const Eigen::Matrix<double, 6, 3> Pt = Phi_CB_.middleCols<3>(6 * a), Pr = Phi_CB_.middleCols<3>(6 * a + 3);
    S.leftCols<3>() += Pt;
    S.rightCols<3>() +=
        Pr * LeftJacobianInverse<double>(Eigen::Vector3d(q.segment<3>(6 * a + 3))) - Pt * Skew<double>(r);
  }
  return S;
}

FrameSolution SuperelementBody::GuessFrame(const BodyConfiguration& c) const {
  FrameSolution frame;
  frame.R = c.R[0] * R0_[0].transpose();
  frame.x = c.x[0] - frame.R * X_[0];
  return frame;
}

FrameSolution SuperelementBody::SolveFrameFrom(const BodyConfiguration& c, const FrameSolution& last,
                                               Eigen::VectorXd* q_scratch,
                                               const Eigen::Matrix<double, 6, 6>* S_inv) const {
  Eigen::VectorXd own;
  Eigen::VectorXd& q = q_scratch ? *q_scratch : own;
  FrameSolution frame = SolveFrame(c, last, &q, S_inv);
  if (!frame.ok && S_inv) frame = SolveFrame(c, last, &q);
  return frame.ok ? frame : SolveFrame(c, GuessFrame(c), &q);
}

FrameSolution SuperelementBody::SolveFrame(const BodyConfiguration& c, const FrameSolution& guess,
                                           Eigen::VectorXd* q_scratch, const Eigen::Matrix<double, 6, 6>* S_inv) const {
  Eigen::VectorXd own;
  Eigen::VectorXd& q = q_scratch ? *q_scratch : own;
  FrameSolution frame = guess;
  frame.ok = false;
  // Translations relative to the body size, plus the round-off of the absolute positions (a
  // body 1e4 m from the origin knows its node positions to 2e-12 m only); rotations as they are.
  double size = 0.0, far = 0.0;
  for (int k = 0; k < n_nodes_; ++k) size = std::max(size, X_[k].norm());
  for (const Eigen::Vector3d& x : c.x) far = std::max(far, x.norm());
  const double tolerance = 1e-13 * size + 32 * std::numeric_limits<double>::epsilon() * far;
  for (int it = 0; it < 30; ++it) {
    LocalCoordinates(c, frame, q);
    Eigen::Matrix<double, 6, 1> g;
    g.noalias() = Phi_CB_ * q;
    frame.iterations = it;
    if (g.head<3>().norm() <= std::max(tolerance, 1e-300) && g.tail<3>().norm() <= 1e-13) {
      // A root with local rotations beyond kMaxLocalRotation is a spurious branch of the log
      // map (far start), not an elastic state: report failure.
      frame.ok = true;
      for (int k = 0; k < n_nodes_; ++k) frame.ok &= q.segment<3>(6 * k + 3).norm() < kMaxLocalRotation;
      return frame;
    }
    // d q_loc = -D Phi_rig zeta for a frame variation zeta (frame axes): zeta = S^-1 g (with
    // the given S^-1: a chord iteration).
    const Eigen::Matrix<double, 6, 1> zeta = S_inv ? (*S_inv * g).eval() : FrameMatrix(q).lu().solve(g);
    frame.x += frame.R * zeta.head<3>();
    frame.R = frame.R * ExpSO3(zeta.tail<3>());
  }
  return frame;
}

}  // namespace femb
