#include "reducer/linalg/sparse_cholesky.h"

#include <sys/resource.h>

#include <Eigen/CholmodSupport>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace femb {
namespace {

// Gives access to the CHOLMOD factor that Eigen keeps protected (for size and flop figures).
class Cholmod : public Eigen::CholmodSupernodalLLT<SparseMatrix, Eigen::Lower> {
 public:
  const cholmod_factor* factor() const { return m_cholmodFactor; }
};

const char* OrderingName(int ordering) {
  switch (ordering) {
    case CHOLMOD_NATURAL:
      return "natural";
    case CHOLMOD_AMD:
      return "amd";
    case CHOLMOD_METIS:
      return "metis";
    case CHOLMOD_NESDIS:
      return "nesdis";
    case CHOLMOD_COLAMD:
      return "colamd";
    default:
      return "other";
  }
}

}  // namespace

struct SparseCholesky::Impl {
  Cholmod solver;
};

SparseCholesky::SparseCholesky() : impl_(std::make_unique<Impl>()) {
  cholmod_common& c = impl_->solver.cholmod();
  c.nmethods = 1;
  c.method[0].ordering = CHOLMOD_METIS;
  c.postorder = 1;
}

SparseCholesky::~SparseCholesky() = default;

double AvailableMemoryBytes() {
  std::ifstream in("/proc/meminfo");
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    std::string key;
    double kib = 0;
    if (fields >> key >> kib && key == "MemAvailable:") return kib * 1024.0;
  }
  return 0.0;
}

double PeakResidentBytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return double(usage.ru_maxrss) * 1024.0;  // Linux: kilobytes
}

FactorizationInfo SparseCholesky::Compute(const SparseMatrix& A, double memory_limit_bytes) {
  FactorizationInfo info;
  rows_ = A.rows();
  if (A.rows() == 0) {
    info.ok = true;
    return info;
  }
  // Symbolic analysis: ordering and supernodes fix the size of L and the flop count.
  auto t0 = std::chrono::steady_clock::now();
  impl_->solver.analyzePattern(A);
  info.analyze_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const cholmod_common& c = impl_->solver.cholmod();
  const cholmod_factor* L = impl_->solver.factor();
  info.flops = c.fl;
  info.ordering = L ? OrderingName(L->ordering) : "none";
  if (L) {
    info.factor_entries = L->is_super ? double(L->xsize) : double(c.lnz);
    info.factor_bytes = 8.0 * info.factor_entries;
  }
  if (memory_limit_bytes > 0 && info.factor_bytes > memory_limit_bytes) {
    char buffer[200];
    std::snprintf(buffer, sizeof buffer, "the Cholesky factor would need %.3g GB, more than the %.3g GB available",
                  info.factor_bytes / 1e9, memory_limit_bytes / 1e9);
    info.ok = false;
    info.too_big = true;
    info.message = buffer;
    return info;
  }
  t0 = std::chrono::steady_clock::now();
  impl_->solver.factorize(A);
  info.numeric_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (impl_->solver.info() != Eigen::Success || c.status == CHOLMOD_NOT_POSDEF) {
    info.ok = false;
    info.message = "matrix is not positive definite (CHOLMOD stopped at column " +
                   std::to_string(L ? long(L->minor) : -1) + " of " + std::to_string(A.rows()) + ")";
    return info;
  }
  info.ok = true;
  return info;
}

Eigen::MatrixXd SparseCholesky::Solve(const Eigen::MatrixXd& B) const {
  solves_ += B.cols();
  if (rows_ == 0) return Eigen::MatrixXd(0, B.cols());
  return impl_->solver.solve(B);
}

void SparseCholesky::Solve(const double* b, double* x) const {
  ++solves_;
  if (rows_ == 0) return;
  Eigen::Map<const Eigen::VectorXd> bv(b, rows_);
  Eigen::Map<Eigen::VectorXd> xv(x, rows_);
  xv = impl_->solver.solve(bv);
}

}  // namespace femb
