// Sparse Cholesky factorization A = L L^T by CHOLMOD's supernodal method (BLAS-3 through
// OpenBLAS) with a METIS nested-dissection ordering, through Eigen's CholmodSupport. One factor
// serves every solve of the reduction: static modes, shift-invert eigen solves, modal derivatives.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>

#include "reducer/fe/fe_model.h"

namespace femb {

/// Outcome of a factorization: a status the caller must look at.
struct FactorizationInfo {
  bool ok = false;
  std::string message;            ///< why it failed (not positive definite at column k, ...)
  double factor_entries = 0;      ///< nonzeros stored in L
  double factor_bytes = 0;        ///< memory of L
  double flops = 0;               ///< floating-point operations of the numeric factorization
  double analyze_seconds = 0;     ///< ordering and symbolic factorization
  double numeric_seconds = 0;     ///< numeric factorization (the flops above)
  std::string ordering;           ///< ordering CHOLMOD used ("metis", "amd", ...)
  bool too_big = false;           ///< refused before the numeric factorization: L would exceed the memory limit
  bool resource_failure = false;  ///< failed for lack of workspace or memory, not for the matrix
};

/// MemAvailable of /proc/meminfo in bytes (0 when unknown).
double AvailableMemoryBytes();
/// Peak resident memory of this process so far, bytes.
double PeakResidentBytes();

class SparseCholesky {
 public:
  SparseCholesky();
  ~SparseCholesky();
  SparseCholesky(const SparseCholesky&) = delete;
  SparseCholesky& operator=(const SparseCholesky&) = delete;

  /// Factorizes the symmetric positive definite A (lower triangle is read). The symbolic
  /// analysis (ordering, supernodes) comes first and gives the size of L; when
  /// `memory_limit_bytes` > 0 and L would be larger, nothing more is done (info.too_big).
  FactorizationInfo Compute(const SparseMatrix& A, double memory_limit_bytes = 0);
  /// X = A^-1 B. Precondition: Compute() succeeded.
  Eigen::MatrixXd Solve(const Eigen::MatrixXd& B) const;
  void Solve(const double* b, double* x) const;
  long rows() const { return rows_; }
  long solves() const { return solves_; }  ///< right-hand sides solved so far

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  long rows_ = 0;
  mutable long solves_ = 0;
};

}  // namespace femb
