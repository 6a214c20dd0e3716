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

/// The same for K x = lambda M x restricted to C x = 0 (C: `constraints`, c x n, may have no
/// rows), with the shift-invert solve given as a function. The dense fallback projects on the
/// null space of C.
EigenResult LowestConstrainedEigenpairs(const SparseMatrix& K, const SparseMatrix& M, const Eigen::MatrixXd& constraints,
                                        int nev, double sigma, const ShiftInvertFn& solve, long dense_limit = 200);

}  // namespace femb
