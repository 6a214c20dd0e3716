#include "reducer/linalg/generalized_eigen.h"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymGEigsShiftSolver.h>
#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace femb {
namespace {

// Spectra's shift-invert operator y = (K - sigma M)^-1 x through a solve made once elsewhere
// (a CHOLMOD factor). Spectra's own SymShiftInvert would refactorize with SparseLU (measured
// 70x slower).
class SolveShiftInvertOp {
 public:
  using Scalar = double;
  SolveShiftInvertOp(const ShiftInvertFn* solve, long n, double sigma) : solve_(solve), n_(n), sigma_(sigma) {}
  Eigen::Index rows() const { return n_; }
  Eigen::Index cols() const { return n_; }
  void set_shift(const Scalar& sigma) {
    if (sigma != sigma_) throw std::logic_error("SolveShiftInvertOp: shift differs from the factor's");
  }
  void perform_op(const Scalar* x_in, Scalar* y_out) const {
    ++calls_;
    (*solve_)(x_in, y_out);
  }
  long calls() const { return calls_; }

 private:
  const ShiftInvertFn* solve_;
  long n_;
  double sigma_;
  mutable long calls_ = 0;
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
  const ShiftInvertFn solve = [&factor](const double* b, double* x) { factor.Solve(b, x); };
  return LowestConstrainedEigenpairs(K, M, Eigen::MatrixXd(0, K.rows()), nev, sigma, solve, dense_limit);
}

EigenResult LowestConstrainedEigenpairs(const SparseMatrix& K, const SparseMatrix& M, const Eigen::MatrixXd& C,
                                        int nev, double sigma, const ShiftInvertFn& solve, long dense_limit) {
  EigenResult result;
  const long n = K.rows();
  const long n_free = n - C.rows();
  if (nev <= 0) {
    result.ok = true;
    result.vectors.resize(n, 0);
    return result;
  }
  if (nev > n_free) {
    result.message = "asked for " + std::to_string(nev) + " eigenpairs of a " + std::to_string(n_free) +
                     "-DOF problem";
    return result;
  }
  if (n <= dense_limit || 2 * nev + 1 > n_free) {
    // Basis Z of the null space of C (all of R^n without constraints).
    Eigen::MatrixXd Z = Eigen::MatrixXd::Identity(n, n);
    if (C.rows() > 0) {
      Eigen::FullPivLU<Eigen::MatrixXd> lu(C);
      Z = lu.kernel();
    }
    const Eigen::MatrixXd K_dense = Z.transpose() * (K * Z), M_dense = Z.transpose() * (M * Z);
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> dense(K_dense, M_dense);
    if (dense.info() != Eigen::Success) {
      result.message = "dense generalized eigen solver failed (is M positive definite?)";
      return result;
    }
    result.lambda = dense.eigenvalues().head(nev);
    result.vectors = Z * dense.eigenvectors().leftCols(nev);
    result.dense = true;
    result.ok = true;
    return result;
  }
  SolveShiftInvertOp op(&solve, n, sigma);
  Spectra::SparseSymMatProd<double> Bop(M);
  const Eigen::Index ncv = std::min<Eigen::Index>(n_free, std::max<Eigen::Index>(2 * nev + 1, 20));
  Spectra::SymGEigsShiftSolver<SolveShiftInvertOp, Spectra::SparseSymMatProd<double>,
                               Spectra::GEigsMode::ShiftInvert>
      solver(op, Bop, nev, ncv, sigma);
  if (C.rows() > 0) {
    // Start inside the constrained space (the operator's range), so that no Ritz vector keeps a
    // component that violates C x = 0.
    Eigen::VectorXd r = Eigen::VectorXd::Random(n), start(n);
    const Eigen::VectorXd Mr = M * r;
    op.perform_op(Mr.data(), start.data());
    solver.init(start.data());
  } else {
    solver.init();
  }
  const Eigen::Index converged = solver.compute(Spectra::SortRule::LargestMagn, 1000, 1e-10,
                                                Spectra::SortRule::SmallestAlge);
  result.linear_solves = op.calls();
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
