// Lowest eigenpairs of K x = lambda M x (K, M symmetric; K - sigma M positive definite) by
// shift-invert Lanczos (Spectra) around sigma, reusing a CHOLMOD factor of K - sigma M held by
// pointer. Tiny problems use a dense solver.
#pragma once

#include <Eigen/Core>
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

}  // namespace femb
