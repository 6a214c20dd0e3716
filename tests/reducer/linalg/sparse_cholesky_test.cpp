// CHOLMOD's factor through SparseCholesky (reducer/linalg/sparse_cholesky.h) against closed
// forms: a chain of n unit springs held at both ends, K = tridiag(-1, 2, -1), loaded by a unit
// force at every node, deflects as x_i = i (n + 1 - i) / 2 (the discrete string under a uniform
// load); a matrix that is not positive definite and a factor over the memory limit are refused
// with a status, not a wrong solve.
#include "reducer/linalg/sparse_cholesky.h"

#include <gtest/gtest.h>

#include <vector>

namespace femb {
namespace {

SparseMatrix Chain(int n, double end = 2.0) {
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < n; ++i) {
    t.emplace_back(i, i, i == 0 ? end : 2.0);
    if (i + 1 < n) {
      t.emplace_back(i + 1, i, -1.0);
      t.emplace_back(i, i + 1, -1.0);
    }
  }
  SparseMatrix K(n, n);
  K.setFromTriplets(t.begin(), t.end());
  return K;
}

TEST(SparseCholesky, AChainUnderAUniformLoadDeflectsAsTheDiscreteString) {
  const int n = 3000;
  SparseCholesky factor;
  const FactorizationInfo info = factor.Compute(Chain(n));
  ASSERT_TRUE(info.ok) << info.message;
  EXPECT_GE(info.factor_entries, n);  // at least the diagonal
  EXPECT_GT(info.factor_bytes, 0);
  const Eigen::MatrixXd x = factor.Solve(Eigen::MatrixXd::Ones(n, 1));
  double worst = 0;
  for (int i = 1; i <= n; ++i) worst = std::max(worst, std::abs(x(i - 1, 0) - 0.5 * i * (n + 1 - i)));
  // Condition number ~ 4 n^2 / pi^2 = 3.6e6: 1e-9 of the largest deflection (1.1e6) leaves room.
  EXPECT_LT(worst, 1e-9 * 0.25 * n * n);
  // The pointer form solves the same, and counts its right-hand sides.
  Eigen::VectorXd b = Eigen::VectorXd::Ones(n), y(n);
  factor.Solve(b.data(), y.data());
  EXPECT_LT((y - x.col(0)).cwiseAbs().maxCoeff(), 1e-12 * x.cwiseAbs().maxCoeff());
  EXPECT_EQ(factor.solves(), 2);
}

TEST(SparseCholesky, ANonPositiveMatrixIsRefusedWithAStatus) {
  SparseCholesky factor;
  const FactorizationInfo info = factor.Compute(Chain(50, -1.0));  // the first spring pulls the wrong way
  EXPECT_FALSE(info.ok);
  EXPECT_FALSE(info.message.empty());
}

TEST(SparseCholesky, AFactorOverTheMemoryLimitIsRefusedBeforeItIsComputed) {
  SparseCholesky factor;
  const FactorizationInfo info = factor.Compute(Chain(2000), 1000.0);  // 1 kB: less than L's diagonal alone
  EXPECT_FALSE(info.ok);
  EXPECT_TRUE(info.too_big);
  EXPECT_GT(info.factor_bytes, 1000.0);
}

}  // namespace
}  // namespace femb
