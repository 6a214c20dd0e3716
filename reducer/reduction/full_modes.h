// Free-free frequencies of the unreduced model, for judging the reduction: the lowest eigenpairs
// of K x = lambda M x by shift-invert around sigma = -s < 0 (K - sigma M = K + s M is positive
// definite although K is singular), with one CHOLMOD factor.
#pragma once

#include <Eigen/Core>
#include <string>

#include "reducer/fe/fe_model.h"
#include "reducer/linalg/sparse_cholesky.h"

namespace femb {

struct FullModesResult {
  bool ok = false;
  std::string message;
  Eigen::VectorXd frequencies_hz;  ///< ascending, the 6 rigid-body ones first
  FactorizationInfo factorization;
  long linear_solves = 0;
};

/// The 6 rigid-body and `n_flexible` lowest flexible frequencies. `s` > 0 is the shift size
/// (a fraction of the lowest expected flexible eigenvalue is a good choice). With `vectors`,
/// also the M-orthonormal mode shapes (n_dofs x (6 + n_flexible), ascending) and, with
/// `lambda`, their eigenvalues.
FullModesResult FullFreeFreeFrequencies(const FeModel& model, int n_flexible, double s,
                                        Eigen::MatrixXd* vectors = nullptr, Eigen::VectorXd* lambda = nullptr);

}  // namespace femb
