// Prints this machine's DGEMM rate (GFLOP/s) through the BLAS that CHOLMOD uses (OpenBLAS):
// the ceiling against which the supernodal factorization is judged. n = 2000, best of 3.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

extern "C" void dgemm_(const char* ta, const char* tb, const int* m, const int* n, const int* k, const double* alpha,
                       const double* a, const int* lda, const double* b, const int* ldb, const double* beta, double* c,
                       const int* ldc);

int main() {
  const int n = 2000;
  std::vector<double> a(std::size_t(n) * n, 1.0 / 3), b(std::size_t(n) * n, 0.5), c(std::size_t(n) * n, 0.0);
  const double one = 1.0, zero = 0.0;
  double best = 0.0;
  for (int r = 0; r < 3; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    dgemm_("N", "N", &n, &n, &n, &one, a.data(), &n, b.data(), &n, &zero, c.data(), &n);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    best = std::max(best, 2.0 * n * n * double(n) / s / 1e9);
  }
  std::printf("%.2f GFLOP/s DGEMM n=%d\n", best, n);
  return c[0] == 0.0;
}
