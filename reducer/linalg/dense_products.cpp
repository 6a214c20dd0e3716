#include "reducer/linalg/dense_products.h"

#include <algorithm>
#include <stdexcept>

// The Fortran BLAS entry (libblas.so.3: OpenBLAS through Debian's alternatives, scripts/setup.sh).
extern "C" void dgemm_(const char* transa, const char* transb, const int* m, const int* n, const int* k,
                       const double* alpha, const double* a, const int* lda, const double* b, const int* ldb,
                       const double* beta, double* c, const int* ldc);

namespace femb {

void Gemm(const Eigen::Ref<const Eigen::MatrixXd>& A, bool transpose_a, const Eigen::Ref<const Eigen::MatrixXd>& B,
          bool transpose_b, Eigen::Ref<Eigen::MatrixXd> C, double alpha, double beta) {
  const Eigen::Index m = transpose_a ? A.cols() : A.rows(), k = transpose_a ? A.rows() : A.cols();
  const Eigen::Index n = transpose_b ? B.rows() : B.cols(), k_b = transpose_b ? B.cols() : B.rows();
  if (k != k_b || C.rows() != m || C.cols() != n) throw std::logic_error("Gemm: sizes do not match");
  if (m == 0 || n == 0) return;
  if (k == 0) {  // an empty sum: beta C
    if (beta == 0.0) {
      C.setZero();
    } else {
      C *= beta;
    }
    return;
  }
  const int mi = int(m), ni = int(n), ki = int(k);
  const int lda = int(std::max<Eigen::Index>(1, A.outerStride())),
            ldb = int(std::max<Eigen::Index>(1, B.outerStride()));
  const int ldc = int(std::max<Eigen::Index>(1, C.outerStride()));
  dgemm_(transpose_a ? "T" : "N", transpose_b ? "T" : "N", &mi, &ni, &ki, &alpha, A.data(), &lda, B.data(), &ldb, &beta,
         C.data(), &ldc);
}

Eigen::MatrixXd Times(const Eigen::Ref<const Eigen::MatrixXd>& A, const Eigen::Ref<const Eigen::MatrixXd>& B) {
  Eigen::MatrixXd C(A.rows(), B.cols());
  Gemm(A, false, B, false, C);
  return C;
}

Eigen::MatrixXd TransposeTimes(const Eigen::Ref<const Eigen::MatrixXd>& A, const Eigen::Ref<const Eigen::MatrixXd>& B) {
  Eigen::MatrixXd C(A.cols(), B.cols());
  Gemm(A, true, B, false, C);
  return C;
}

}  // namespace femb
