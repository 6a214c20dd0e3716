// Lowest eigenpairs of K x = lambda M x (K, M symmetric; K - sigma M positive definite) by
// shift-invert Lanczos (Spectra) around sigma, reusing a CHOLMOD factor of K - sigma M held by
// pointer. Tiny problems use a dense solver.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>

#include "reducer/fe/fe_model.h"
#include "reducer/linalg/sparse_cholesky.h"

namespace femb {

struct EigenResult {
  bool ok = false;
  std::string message;
  Eigen::VectorXd lambda;   ///< ascending
  Eigen::MatrixXd vectors;  ///< M-orthonormal columns
  long linear_solves = 0;   ///< solves with the factor (shift-invert operations)
  bool dense = false;       ///< true when the dense fallback was used
};

/// `factor` must hold K - sigma M. Below `dense_limit` rows, a dense solver is used instead.
EigenResult LowestEigenpairs(const SparseMatrix& K, const SparseMatrix& M, int nev, double sigma,
                             const SparseCholesky& factor, long dense_limit = 200);

/// y = (K - sigma M)^-1 x on the subspace C x = 0: the x of (K - sigma M) x + C^T mu = b, C x = 0.
using ShiftInvertFn = std::function<void(const double* b, double* x)>;

/// X = (K - sigma M)^-1 B on the subspace C x = 0 for a block of right-hand sides B (n x k):
/// one pass over a sparse factor serves all k columns (BLAS-3).
using BlockShiftInvertFn = std::function<Eigen::MatrixXd(const Eigen::MatrixXd& B)>;

/// Lowest eigenpairs of K x = lambda M x on C x = 0 by block shift-invert Lanczos in the M inner
/// product with full reorthogonalization and Rayleigh-Ritz on the whole basis: the factor is
/// read once per block of `block` vectors instead of once per vector (the single-vector solves
/// of plain Lanczos are bound by memory bandwidth). Converged when every wanted Ritz pair has
/// ||A x - theta x||_M <= tol |theta|, A = (K - sigma M)^-1 M. linear_solves counts right-hand
/// sides; `block_solves` (if given) receives the number of passes over the factor.
EigenResult BlockLanczosEigenpairs(const SparseMatrix& K, const SparseMatrix& M, const Eigen::MatrixXd& constraints,
                                   int nev, double sigma, const BlockShiftInvertFn& solve, int block = 8,
                                   double tol = 1e-10, long* block_solves = nullptr);

/// The same for K x = lambda M x restricted to C x = 0 (C: `constraints`, c x n, may have no
/// rows), with the shift-invert solve given as a function. The dense fallback projects on the
/// null space of C.
EigenResult LowestConstrainedEigenpairs(const SparseMatrix& K, const SparseMatrix& M,
                                        const Eigen::MatrixXd& constraints, int nev, double sigma,
                                        const ShiftInvertFn& solve, long dense_limit = 200);

}  // namespace femb
