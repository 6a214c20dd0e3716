#include "reducer/linalg/generalized_eigen.h"

#include <Eigen/Eigenvalues>
#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymGEigsShiftSolver.h>
#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace femb {
namespace {

// Spectra's shift-invert operator y = (K - sigma M)^-1 x, on a factor made once elsewhere.
// Spectra's own SymShiftInvert would refactorize with SparseLU (measured 70x slower).
class FactorShiftInvertOp {
 public:
  using Scalar = double;
  FactorShiftInvertOp(const SparseCholesky* factor, double sigma) : factor_(factor), sigma_(sigma) {}
  Eigen::Index rows() const { return factor_->rows(); }
  Eigen::Index cols() const { return factor_->rows(); }
  void set_shift(const Scalar& sigma) {
    if (sigma != sigma_) throw std::logic_error("FactorShiftInvertOp: shift differs from the factor's");
  }
  void perform_op(const Scalar* x_in, Scalar* y_out) const { factor_->Solve(x_in, y_out); }

 private:
  const SparseCholesky* factor_;
  double sigma_;
};

void SortAscending(EigenResult& r) {
  std::vector<int> order(r.lambda.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return r.lambda[a] < r.lambda[b]; });
  Eigen::VectorXd lambda(r.lambda.size());
  Eigen::MatrixXd vectors(r.vectors.rows(), r.vectors.cols());
  for (size_t i = 0; i < order.size(); ++i) {
    lambda[i] = r.lambda[order[i]];
    vectors.col(i) = r.vectors.col(order[i]);
  }
  r.lambda = lambda;
  r.vectors = vectors;
}

}  // namespace

EigenResult LowestEigenpairs(const SparseMatrix& K, const SparseMatrix& M, int nev, double sigma,
                             const SparseCholesky& factor, long dense_limit) {
  EigenResult result;
  const long n = K.rows();
  if (nev <= 0) {
    result.ok = true;
    result.vectors.resize(n, 0);
    return result;
  }
  if (nev > n) {
    result.message = "asked for " + std::to_string(nev) + " eigenpairs of a " + std::to_string(n) +
                     "-DOF problem";
    return result;
  }
  if (n <= dense_limit || 2 * nev + 1 > n) {
    const Eigen::MatrixXd K_dense(K), M_dense(M);
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> dense(K_dense, M_dense);
    if (dense.info() != Eigen::Success) {
      result.message = "dense generalized eigen solver failed (is M positive definite?)";
      return result;
    }
    result.lambda = dense.eigenvalues().head(nev);
    result.vectors = dense.eigenvectors().leftCols(nev);
    result.dense = true;
    result.ok = true;
    return result;
  }
  const long solves_before = factor.solves();
  FactorShiftInvertOp op(&factor, sigma);
  Spectra::SparseSymMatProd<double> Bop(M);
  const Eigen::Index ncv = std::min<Eigen::Index>(n, std::max<Eigen::Index>(2 * nev + 1, 20));
  Spectra::SymGEigsShiftSolver<FactorShiftInvertOp, Spectra::SparseSymMatProd<double>,
                               Spectra::GEigsMode::ShiftInvert>
      solver(op, Bop, nev, ncv, sigma);
  solver.init();
  const Eigen::Index converged = solver.compute(Spectra::SortRule::LargestMagn, 1000, 1e-10,
                                                Spectra::SortRule::SmallestAlge);
  result.linear_solves = factor.solves() - solves_before;
  if (solver.info() != Spectra::CompInfo::Successful || converged < nev) {
    result.message = "shift-invert Lanczos converged " + std::to_string(converged) + " of " +
                     std::to_string(nev) + " eigenpairs";
    return result;
  }
  result.lambda = solver.eigenvalues();
  result.vectors = solver.eigenvectors();
  SortAscending(result);
  result.ok = true;
  return result;
}

}  // namespace femb
