// Block helpers of the superelement body's kernels (solver/body/*.cpp):
// node vectors and matrices turned by 3 x 3 blocks, the exact derivative of a quadratic function.
// Internal to the solver: solver/body, and generalized-alpha's kept inertia matrices.
#pragma once

#include <Eigen/Core>
#include <algorithm>

namespace femb::body_blocks {

// The derivative of a quadratic function g of a 3-vector at w, exactly (no truncation):
// Dg(w) e = [g(w + s e) - g(w) - g(s e)] / s for any s > 0.
template <class Quadratic>
Eigen::Matrix3d QuadraticDerivative(const Eigen::Vector3d& w, const Quadratic& g) {
  const double s = std::max(w.norm(), 1.0);
  const Eigen::Vector3d g0 = g(w);
  Eigen::Matrix3d D;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d e = s * Eigen::Vector3d::Unit(i);
    D.col(i) = (g(Eigen::Vector3d(w + e)) - g0 - g(e)) / s;
  }
  return D;
}

// out = R applied to the first `blocks` 3-vectors of v (node forces and moments; modal rows as
// they are), into out's storage (out may be v itself).
inline void TurnBlocksInto(const Eigen::Matrix3d& R, const Eigen::VectorXd& v, int blocks, Eigen::VectorXd& out) {
  if (&out != &v) out = v;
  for (int a = 0; a < blocks; ++a) {
    const Eigen::Vector3d x = out.segment<3>(3 * a);
    out.segment<3>(3 * a) = R * x;
  }
}

// X <- blockdiag(A(0), ..., A(blocks - 1), 1) X in place: the first `blocks` row triples each
// turned by its 3 x 3 matrix A(a), column by column (fixed-size products, no temporaries; a
// dense n x n product with the block-diagonal Rbar would cost n / 3 times more).
template <class Blocks>
void TurnRowBlocks(Eigen::MatrixXd& X, int blocks, const Blocks& A) {
  for (int a = 0; a < blocks; ++a) {
    const Eigen::Matrix3d Aa = A(a);
    for (Eigen::Index j = 0; j < X.cols(); ++j) {
      const Eigen::Vector3d x = X.block<3, 1>(3 * a, j);
      X.block<3, 1>(3 * a, j) = Aa * x;
    }
  }
}

// X <- X blockdiag(A(0), ..., A(blocks - 1), 1) in place, row by row.
template <class Blocks>
void TurnColBlocks(Eigen::MatrixXd& X, int blocks, const Blocks& A) {
  for (int a = 0; a < blocks; ++a) {
    const Eigen::Matrix3d Aa = A(a);
    for (Eigen::Index i = 0; i < X.rows(); ++i) {
      const Eigen::RowVector3d x = X.block<1, 3>(i, 3 * a);
      X.block<1, 3>(i, 3 * a) = x * Aa;
    }
  }
}

// X <- Rbar X Rbar^T in place, Rbar = blockdiag(R, ..., R, 1) over the first `blocks` triples: a
// node matrix turned with the body (its frame's R, or R^T back into the frame).
inline void TurnNodeBlocks(Eigen::MatrixXd& X, int blocks, const Eigen::Matrix3d& R) {
  TurnRowBlocks(X, blocks, [&](int) { return R; });
  const Eigen::Matrix3d Rt = R.transpose();
  TurnColBlocks(X, blocks, [&](int) { return Rt; });
}
}  // namespace femb::body_blocks
