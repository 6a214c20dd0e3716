#include "reducer/linalg/generalized_eigen.h"

#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymGEigsShiftSolver.h>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <numeric>
#include <stdexcept>

#include "reducer/linalg/dense_products.h"

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

// No eigenpairs asked (ok, no vectors) or more than the n_free unconstrained DOFs (an error):
// true when `result` is final.
bool NothingToSolve(int nev, long n, long n_free, EigenResult* result) {
  if (nev <= 0) {
    result->ok = true;
    result->vectors.resize(n, 0);
    return true;
  }
  if (nev > n_free) {
    result->message =
        "asked for " + std::to_string(nev) + " eigenpairs of a " + std::to_string(n_free) + "-DOF problem";
    return true;
  }
  return false;
}

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

EigenResult LowestConstrainedEigenpairs(const SparseMatrix& K, const SparseMatrix& M, const Eigen::MatrixXd& C, int nev,
                                        double sigma, const ShiftInvertFn& solve, long dense_limit) {
  EigenResult result;
  const long n = K.rows();
  const long n_free = n - C.rows();
  if (NothingToSolve(nev, n, n_free, &result)) return result;
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
  Spectra::SymGEigsShiftSolver<SolveShiftInvertOp, Spectra::SparseSymMatProd<double>, Spectra::GEigsMode::ShiftInvert>
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
  const Eigen::Index converged =
      solver.compute(Spectra::SortRule::LargestMagn, 1000, 1e-10, Spectra::SortRule::SmallestAlge);
  result.linear_solves = op.calls();
  if (solver.info() != Spectra::CompInfo::Successful || converged < nev) {
    result.message =
        "shift-invert Lanczos converged " + std::to_string(converged) + " of " + std::to_string(nev) + " eigenpairs";
    return result;
  }
  result.lambda = solver.eigenvalues();
  result.vectors = solver.eigenvectors();
  SortAscending(result);
  result.ok = true;
  return result;
}

EigenResult BlockLanczosEigenpairs(const SparseMatrix& K, const SparseMatrix& M, const Eigen::MatrixXd& C, int nev,
                                   double sigma, const BlockShiftInvertFn& solve, int block, double tol,
                                   long* block_solves) {
  EigenResult result;
  const long n = K.rows();
  const long n_free = n - C.rows();
  if (NothingToSolve(nev, n, n_free, &result)) return result;
  const long max_basis = std::min<long>(n_free, std::max<long>(12L * nev, 200));
  long passes = 0;
  // A X = (K - sigma M)^-1 M X on C x = 0, from M X.
  auto apply = [&](const Eigen::MatrixXd& MX) {
    ++passes;
    result.linear_solves += MX.cols();
    return solve(MX);
  };
  // M-orthonormalizes W (with MW = M W carried along: sparse products with M are the costly
  // part after the solves) by Cholesky QR twice, dropping directions that vanish.
  auto orthonormalize = [&](Eigen::MatrixXd& W, Eigen::MatrixXd& MW) {
    for (int pass = 0; pass < 2; ++pass) {
      const Eigen::MatrixXd G = TransposeTimes(W, MW);
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (G + G.transpose()));
      const double top = es.eigenvalues().maxCoeff();
      std::vector<int> keep;
      for (int k = 0; k < G.rows(); ++k)
        if (es.eigenvalues()[k] > 1e-20 * top && es.eigenvalues()[k] > 0) keep.push_back(k);
      Eigen::MatrixXd basis(G.rows(), long(keep.size()));
      for (size_t k = 0; k < keep.size(); ++k)
        basis.col(long(k)) = es.eigenvectors().col(keep[k]) / std::sqrt(es.eigenvalues()[keep[k]]);
      W = Times(W, basis);
      MW = Times(MW, basis);
    }
  };
  // Basis V (M-orthonormal), A V and M V, stored in matrices that grow by half their width
  // when full (no copy of the whole basis at every step); m columns are in use.
  Eigen::MatrixXd V(n, 0), MV(n, 0), T(0, 0);
  long m = 0;
  auto reserve = [&](long columns) {
    if (columns <= V.cols()) return;
    const long capacity = std::min(max_basis + block, std::max(columns, V.cols() + V.cols() / 2));
    V.conservativeResize(n, capacity);
    MV.conservativeResize(n, capacity);
  };
  // Start in the operator's range (inside C x = 0).
  const Eigen::MatrixXd start = Eigen::MatrixXd::Random(n, block);
  Eigen::MatrixXd Q = apply(M * start);
  Eigen::MatrixXd MQ = M * Q;
  orthonormalize(Q, MQ);
  while (true) {
    if (Q.cols() == 0) {
      result.message = "block Lanczos: the Krylov space was exhausted";
      return result;
    }
    const long add = Q.cols();
    const Eigen::MatrixXd AQ = apply(MQ);
    reserve(m + add);
    V.middleCols(m, add) = Q;
    MV.middleCols(m, add) = MQ;
    m += add;
    // Rayleigh-Ritz: T = V^T M A V (symmetric: A is self-adjoint in the M inner product),
    // grown by the new block's rows and columns.
    T.conservativeResize(m, m);
    const Eigen::MatrixXd new_cols = TransposeTimes(MV.leftCols(m), AQ);
    T.rightCols(add) = new_cols;
    T.bottomRows(add) = new_cols.transpose();
    // The next block's direction: A Q orthogonalized against the whole basis (twice). With the
    // block Lanczos relation A V = V T + W E^T, a Ritz pair (theta, V y) has the residual
    // A V y - theta V y = W y_new (y_new: y's rows of the newest block), so its M-norm is
    // sqrt(y_new^T (W^T M W) y_new): no n-sized work to test convergence.
    Eigen::MatrixXd W = AQ;
    for (int pass = 0; pass < 2; ++pass)
      Gemm(V.leftCols(m), false, TransposeTimes(MV.leftCols(m), W), false, W, -1.0, 1.0);
    Eigen::MatrixXd MW = M * W;
    const Eigen::MatrixXd G = TransposeTimes(W, MW);
    if (m >= nev) {
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (T + T.transpose()));
      bool converged = true;
      for (int k = 0; k < nev && converged; ++k) {
        const long col = m - 1 - k;  // largest theta = nearest the shift
        const double theta = es.eigenvalues()[col];
        const Eigen::VectorXd y_new = es.eigenvectors().col(col).tail(add);
        converged = std::sqrt(std::max(y_new.dot(G * y_new), 0.0)) <= tol * std::abs(theta);
      }
      if (converged) {
        Eigen::MatrixXd Y(m, nev);
        result.lambda.resize(nev);
        for (int k = 0; k < nev; ++k) {
          result.lambda[k] = sigma + 1.0 / es.eigenvalues()[m - 1 - k];
          Y.col(k) = es.eigenvectors().col(m - 1 - k);
        }
        result.vectors = Times(V.leftCols(m), Y);
        break;
      }
    }
    if (m + block > max_basis) {
      result.message = "block Lanczos did not converge with " + std::to_string(m) + " basis vectors";
      return result;
    }
    orthonormalize(W, MW);
    Q = std::move(W);
    MQ = std::move(MW);
  }
  if (block_solves) *block_solves = passes;
  SortAscending(result);
  result.ok = true;
  return result;
}

}  // namespace femb
