#include "reducer/reduction/full_modes.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "formats/superelement.h"
#include "reducer/linalg/generalized_eigen.h"
#include "reducer/linalg/shared_columns.h"

namespace femb {
namespace {

// The reduced model's free-free frequencies (dense, small) against the full model's: the first
// and the largest relative error, reported.
void CompareFreeFree(const Superelement& se, const FullModesResult& full, const ProgressFn& report) {
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> reduced(se.K, se.M, Eigen::EigenvaluesOnly);
  if (reduced.info() != Eigen::Success) return;
  double worst = 0.0, first = 0.0;
  int worst_mode = 0, compared = 0;
  for (int k = 6; k < full.frequencies_hz.size() && k < reduced.eigenvalues().size(); ++k) {
    const double f_full = full.frequencies_hz[k], f_reduced = FrequencyHz(reduced.eigenvalues()[k]);
    if (!(f_full > 0)) continue;
    const double error = f_reduced / f_full - 1;
    if (compared++ == 0) first = error;
    if (std::abs(error) > std::abs(worst)) {
      worst = error;
      worst_mode = k - 5;
    }
  }
  if (compared == 0) return;
  char detail[640];
  std::snprintf(detail, sizeof detail,
                "%d flexible free-free frequencies of the reduced model against the full model's: first %+.3g%%, "
                "largest %+.3g%% (mode %d); more modes in the basis lower it (femb-inspect lists them)",
                compared, 100 * first, 100 * worst, worst_mode);
  report("free-free check", 0.0, detail);
}

}  // namespace

FullModesResult FullFreeFreeFrequencies(const FeModel& model, int n_flexible, double s, Eigen::MatrixXd* vectors,
                                        Eigen::VectorXd* lambda) {
  return FullFreeFreeFrequencies(model.K, model.M, n_flexible, s, vectors, lambda);
}

FullModesResult FullFreeFreeFrequencies(const SparseMatrix& K, const SparseMatrix& M, int n_flexible, double s,
                                        Eigen::MatrixXd* vectors, Eigen::VectorXd* lambda) {
  FullModesResult r;
  const int nev = std::min<int>(n_flexible + 6, int(K.rows()));
  SparseMatrix shifted = K + s * M;
  SparseCholesky factor;
  r.factorization = factor.Compute(shifted);
  if (!r.factorization.ok) {
    r.message = "K + s M is not positive definite: " + r.factorization.message;
    return r;
  }
  EigenResult eig = LowestEigenpairs(K, M, nev, -s, factor);
  r.linear_solves = eig.linear_solves;
  if (!eig.ok) {
    r.message = eig.message;
    return r;
  }
  r.frequencies_hz.resize(nev);
  for (int k = 0; k < nev; ++k) r.frequencies_hz[k] = FrequencyHz(eig.lambda[k]);
  if (vectors) *vectors = std::move(eig.vectors);
  if (lambda) *lambda = eig.lambda;
  r.ok = true;
  return r;
}

double LargestDiagonalRatio(const SparseMatrix& K, const SparseMatrix& M) {
  double max_ratio = 0.0;
  for (int j = 0; j < K.outerSize(); ++j) {
    const double m_jj = M.coeff(j, j);
    if (m_jj > 0) max_ratio = std::max(max_ratio, K.coeff(j, j) / m_jj);
  }
  return max_ratio;
}

bool FreeFreeCheck(const PartSpec& part, const FeModel& model, const Eigen::VectorXd& fixed_interface_lambda,
                   const ProgressFn& progress, const ProgressFn& report, Superelement& se, std::string* message) {
  int full_modes = part.reduction.full_modes;
  if (!part.reduction.full_modes_given) {
    full_modes = model.n_dofs() <= ReductionSpec::kFullModesMaxDofs ? std::min(12, se.n_reduced_dofs() - 6) : 0;
    if (full_modes <= 0 && model.n_dofs() > ReductionSpec::kFullModesMaxDofs && progress) {
      progress("free-free check", 0.0,
               "skipped above " + std::to_string(ReductionSpec::kFullModesMaxDofs) +
                   " DOFs (reduction.full_modes: K or --full-modes K computes K)");
    }
  }
  if (full_modes <= 0) return true;
  Stopwatch clock;
  // On MPI ranks sharing K and M by columns every rank solves the whole model (gathered).
  SparseMatrix K_whole, M_whole;
  if (!model.columns.whole()) {
    K_whole = GatherColumns(model.K, model.columns);
    M_whole = GatherColumns(model.M, model.columns);
  }
  const SparseMatrix& K = model.columns.whole() ? model.K : K_whole;
  const SparseMatrix& M = model.columns.whole() ? model.M : M_whole;
  const double s =
      fixed_interface_lambda.size() > 0 ? 1e-2 * fixed_interface_lambda[0] : 1e-8 * LargestDiagonalRatio(K, M);
  const FullModesResult full = FullFreeFreeFrequencies(K, M, full_modes, s);
  if (!full.ok && part.reduction.full_modes_given) {
    *message = "full-model free-free eigen solve failed: " + full.message;
    return false;
  }
  if (!full.ok) {
    report("free-free check", clock.Seconds(),
           "skipped: the full model's free-free eigen solve failed (" + full.message + ")");
    return true;
  }
  se.full_free_free_frequencies_hz = full.frequencies_hz;
  std::string rigid;
  for (const std::string& name : se.full_rigid_couplings) rigid += (rigid.empty() ? "" : ", ") + name;
  char detail[640];
  std::snprintf(detail, sizeof detail, "%d free-free frequencies of the full model%s, %ld linear solves",
                int(full.frequencies_hz.size()),
                rigid.empty() ? "" : (" with the RBE2 couplings of " + rigid + " (their node sets rigid)").c_str(),
                full.linear_solves);
  report("full modes", clock.Seconds(), detail);
  CompareFreeFree(se, full, report);
  return true;
}

}  // namespace femb
