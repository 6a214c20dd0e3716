// Free-free frequencies of the unreduced model, for judging the reduction: the lowest eigenpairs
// of K x = lambda M x by shift-invert around sigma = -s < 0 (K - sigma M = K + s M is positive
// definite although K is singular), with one CHOLMOD factor.
#pragma once

#include <Eigen/Core>
#include <string>

#include "formats/part_file.h"
#include "formats/superelement.h"
#include "reducer/fe/fe_model.h"
#include "reducer/linalg/sparse_cholesky.h"
#include "reducer/progress.h"

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
/// The same for the whole K and M given (FeModel::K and M may be a rank's share of the columns).
FullModesResult FullFreeFreeFrequencies(const SparseMatrix& K, const SparseMatrix& M, int n_flexible, double s,
                                        Eigen::MatrixXd* vectors = nullptr, Eigen::VectorXd* lambda = nullptr);

/// The largest K_jj / M_jj over the DOFs with mass: an eigenvalue scale of the model, for the
/// shift of its free-free eigen solves.
double LargestDiagonalRatio(const SparseMatrix& K, const SparseMatrix& M);

/// The full model's free-free modes against the reduced model's (se.K, se.M): how far the basis
/// carries the free body's own vibration (a free bar's first axial mode 0.43% stiff with 20
/// fixed-interface modes), by default for models up to kFullModesMaxDofs DOFs; into
/// se.full_free_free_frequencies_hz, reported. On MPI ranks sharing K and M by columns every rank
/// solves the whole model (gathered). `fixed_interface_lambda` sets the shift. false with
/// *message when the eigen solve the part asked for fails (one it did not ask for is skipped with
/// a line).
bool FreeFreeCheck(const PartSpec& part, const FeModel& model, const Eigen::VectorXd& fixed_interface_lambda,
                   const ProgressFn& progress, const ProgressFn& report, Superelement& se, std::string* message);

}  // namespace femb
