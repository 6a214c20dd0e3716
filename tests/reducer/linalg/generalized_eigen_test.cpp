// Lowest eigenpairs of K x = lambda M x (reducer/linalg/generalized_eigen.h) against the closed
// form of a chain of n masses m on unit springs k held at both ends:
//   lambda_j = (k / m) (2 - 2 cos(j pi / (n + 1))),  j = 1, 2, ...
// by shift-invert Lanczos above the dense limit and the dense solver below it, and, with the
// first mass held by a constraint row, the same chain one mass shorter (lambda_j with n - 1),
// by block Lanczos. Vectors M-orthonormal, residuals small.
#include "reducer/linalg/generalized_eigen.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <vector>

namespace femb {
namespace {

constexpr double kSpring = 3.0e4, kMass = 0.2;

SparseMatrix Diagonal(int n, double value) {
  SparseMatrix M(n, n);
  M.setIdentity();
  return M * value;
}

SparseMatrix Chain(int n) {
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < n; ++i) {
    t.emplace_back(i, i, 2 * kSpring);
    if (i + 1 < n) {
      t.emplace_back(i + 1, i, -kSpring);
      t.emplace_back(i, i + 1, -kSpring);
    }
  }
  SparseMatrix K(n, n);
  K.setFromTriplets(t.begin(), t.end());
  return K;
}

double Exact(int n, int j) { return kSpring / kMass * (2 - 2 * std::cos(j * M_PI / (n + 1))); }

// `free_from`: the first row free of constraint reactions (the residual K x - lambda M x is the
// constraint's C^T mu on the rows it holds).
void ExpectPairs(const EigenResult& r, const SparseMatrix& K, const SparseMatrix& M, int n_chain, int nev,
                 int free_from = 0) {
  ASSERT_TRUE(r.ok) << r.message;
  ASSERT_EQ(r.lambda.size(), nev);
  for (int j = 1; j <= nev; ++j) EXPECT_NEAR(r.lambda[j - 1], Exact(n_chain, j), 1e-8 * Exact(n_chain, j)) << j;
  const Eigen::MatrixXd& V = r.vectors;
  EXPECT_LT((V.transpose() * (M * V) - Eigen::MatrixXd::Identity(nev, nev)).cwiseAbs().maxCoeff(), 1e-9);
  const Eigen::MatrixXd residual = (K * V - M * V * r.lambda.asDiagonal()).bottomRows(K.rows() - free_from);
  EXPECT_LT(residual.cwiseAbs().maxCoeff(), 1e-6 * r.lambda.maxCoeff() * V.cwiseAbs().maxCoeff());
}

TEST(GeneralizedEigen, ShiftInvertLanczosGivesTheChainsLowestModes) {
  const int n = 600, nev = 8;
  const SparseMatrix K = Chain(n), M = Diagonal(n, kMass);
  const double sigma = -0.5 * Exact(n, 1);  // below the spectrum: K - sigma M positive definite
  SparseCholesky factor;
  ASSERT_TRUE(factor.Compute(SparseMatrix(K - sigma * M)).ok);
  const EigenResult r = LowestEigenpairs(K, M, nev, sigma, factor);
  EXPECT_FALSE(r.dense);
  EXPECT_GT(r.linear_solves, 0);
  ExpectPairs(r, K, M, n, nev);
}

TEST(GeneralizedEigen, TheDenseSolverBelowTheLimitAgrees) {
  const int n = 60, nev = 5;
  const SparseMatrix K = Chain(n), M = Diagonal(n, kMass);
  SparseCholesky factor;
  ASSERT_TRUE(factor.Compute(K).ok);
  const EigenResult r = LowestEigenpairs(K, M, nev, 0.0, factor);
  EXPECT_TRUE(r.dense);
  ExpectPairs(r, K, M, n, nev);
}

TEST(GeneralizedEigen, BlockLanczosOnAConstrainedChainIsTheShorterChain) {
  // x_0 = 0 by a constraint row: the other n - 1 masses are a chain of their own, held at both
  // ends. The shift-invert solve on C x = 0 by the bordered system [K C^T; C 0], factored once.
  const int n = 400, nev = 6;
  const SparseMatrix K = Chain(n), M = Diagonal(n, kMass);
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(1, n);
  C(0, 0) = 1.0;
  Eigen::MatrixXd bordered = Eigen::MatrixXd::Zero(n + 1, n + 1);
  bordered.topLeftCorner(n, n) = Eigen::MatrixXd(K);
  bordered.topRightCorner(n, 1) = C.transpose();
  bordered.bottomLeftCorner(1, n) = C;
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(bordered);
  long passes = 0;
  const BlockShiftInvertFn solve = [&](const Eigen::MatrixXd& B) {
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n + 1, B.cols());
    rhs.topRows(n) = B;
    return Eigen::MatrixXd(lu.solve(rhs).topRows(n));
  };
  const EigenResult r = BlockLanczosEigenpairs(K, M, C, nev, 0.0, solve, 4, 1e-10, &passes);
  EXPECT_GT(passes, 0);
  ExpectPairs(r, K, M, n - 1, nev, 1);
  EXPECT_LT((C * r.vectors).cwiseAbs().maxCoeff(), 1e-12);
}

}  // namespace
}  // namespace femb
