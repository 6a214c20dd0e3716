// The reduction's large dense products (tall bases of n rows times a few dozen columns: the
// block Lanczos basis, the static and modal shapes and their projections) in BLAS, called
// explicitly: OpenBLAS picks its kernels for the processor at run time and runs them on its
// threads.
//
// Why explicit calls and not EIGEN_USE_BLAS: that macro redefines Eigen's product templates, so a program linking the
// reducer and the solver (every test program, the solver benchmarks) had them compiled two ways under the same names, a
// one-definition violation, and the solver's small products ran in whichever the linker kept. The solver is built for
// Eigen's own kernels: femb-solve with EIGEN_USE_BLAS measured 3% slower on one thread and 20% on two (OpenBLAS entered
// from both body threads at once). Measured on the 1e5-DOF crank: the same reduction time, the same matrices to 6e-14.
#pragma once

#include <Eigen/Core>

namespace femb {

/// C = alpha op(A) op(B) + beta C, op = transpose where asked (BLAS dgemm). C must have the
/// product's size; alpha = 1, beta = 0 by default.
void Gemm(const Eigen::Ref<const Eigen::MatrixXd>& A, bool transpose_a, const Eigen::Ref<const Eigen::MatrixXd>& B,
          bool transpose_b, Eigen::Ref<Eigen::MatrixXd> C, double alpha = 1.0, double beta = 0.0);

/// A B in BLAS.
Eigen::MatrixXd Times(const Eigen::Ref<const Eigen::MatrixXd>& A, const Eigen::Ref<const Eigen::MatrixXd>& B);

/// A^T B in BLAS.
Eigen::MatrixXd TransposeTimes(const Eigen::Ref<const Eigen::MatrixXd>& A, const Eigen::Ref<const Eigen::MatrixXd>& B);

}  // namespace femb
