#include "solver/assembly/free_solver.h"

#include <klu.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>

namespace femb {

struct FreeSolver::Klu {
  klu_common common;
  klu_symbolic* symbolic = nullptr;
  klu_numeric* numeric = nullptr;
  // The free block of S in compressed columns; the pattern `symbolic` was analysed for.
  std::vector<int> outer, inner, analysed_outer, analysed_inner;
  std::vector<double> values;
  std::vector<double> pivot_values;  // the values of the last full factorization (FactorMemory)
  // The pivot ratio (min / max |u_ii|) of the last full factorization.
  double rcond = 0.0;
  Klu() {
    klu_defaults(&common);
    common.halt_if_singular = 1;
  }
  ~Klu() { Clear(); }
  void Clear() {
    if (numeric) klu_free_numeric(&numeric, &common);
    if (symbolic) klu_free_symbolic(&symbolic, &common);
  }
  // A full factorization (pivoting) with the kept analysis; false on a zero pivot.
  bool FactorAnew() {
    if (numeric) klu_free_numeric(&numeric, &common);
    numeric = klu_factor(outer.data(), inner.data(), values.data(), symbolic, &common);
    if (!numeric) return false;
    pivot_values.assign(values.begin(), values.end());
    klu_rcond(symbolic, numeric, &common);
    rcond = common.rcond;
    return rcond > 0.0;
  }
};

FreeSolver::FreeSolver() : klu_(std::make_unique<Klu>()) {}
FreeSolver::~FreeSolver() = default;

void FreeSolver::Save(FactorMemory& memory) const {
  const Klu& k = *klu_;
  memory.outer = k.symbolic ? k.analysed_outer : std::vector<int>();
  memory.inner = k.symbolic ? k.analysed_inner : std::vector<int>();
  memory.pivot_values = k.numeric ? k.pivot_values : std::vector<double>();
  memory.analysed = analysed_, memory.full = full_, memory.refactored = refactored_;
}

bool FreeSolver::Restore(const FactorMemory& memory) {
  Klu& k = *klu_;
  k.Clear();
  k.symbolic = nullptr, k.numeric = nullptr;
  valid_ = false;
  analysed_ = memory.analysed, full_ = memory.full, refactored_ = memory.refactored;
  if (memory.outer.empty()) return true;
  const int n = int(memory.outer.size()) - 1;
  if (n < 0 || memory.outer.back() != int(memory.inner.size())) return false;
  k.outer = k.analysed_outer = memory.outer;
  k.inner = k.analysed_inner = memory.inner;
  k.symbolic = klu_analyze(n, k.outer.data(), k.inner.data(), &k.common);
  if (!k.symbolic) return false;
  if (memory.pivot_values.empty()) return true;
  if (memory.pivot_values.size() != memory.inner.size()) return false;
  k.values = memory.pivot_values;
  return k.FactorAnew();
}

bool FreeSolver::Factor(const DofMap& dofs, const SystemMatrix& S) {
  valid_ = false;
  Klu& k = *klu_;
  free_ = dofs.solved();
  const int n = int(free_.size());
  position_.assign(size_t(S.rows()), -1);
  for (int i = 0; i < n; ++i) position_[size_t(free_[size_t(i)])] = i;
  // The free block, column by column (free_ ascending keeps the rows sorted).
  k.outer.assign(size_t(n) + 1, 0);
  k.inner.clear();
  k.values.clear();
  for (int c = 0; c < n; ++c) {
    for (SystemMatrix::InnerIterator it(S, free_[size_t(c)]); it; ++it) {
      const int row = position_[size_t(it.row())];
      if (row < 0) continue;
      if (!std::isfinite(it.value())) return false;
      k.inner.push_back(row);
      k.values.push_back(it.value());
    }
    k.outer[size_t(c) + 1] = int(k.inner.size());
  }
  if (n == 0) return valid_ = true;
  // Loop constraints: the multipliers' rows (G, of order 1) and columns (G^T) meet coordinates
  // whose diagonal may be of order m / (beta h^2) (Arnold & Bruls 2007: the index-3 iteration
  // matrix's condition grows as h^-2 unscaled). Row and column of multiplier i are scaled by
  // s_i, the largest |S_jj| of the coordinates its equation involves: the factor is of D S D,
  // D = diag(1, ..., s_i), and Solve returns D (D S D)^-1 D r.
  scale_.setOnes(n);
  if (dofs.n_multipliers() > 0) {
    Eigen::VectorXd &diagonal = diagonal_, &s = multiplier_scale_;
    diagonal.setZero(n);
    s.setZero(n);
    for (int c = 0; c < n; ++c)
      for (int p = k.outer[size_t(c)]; p < k.outer[size_t(c) + 1]; ++p)
        if (k.inner[size_t(p)] == c) diagonal[c] = std::abs(k.values[size_t(p)]);
    for (int c = 0; c < n; ++c) {
      if (dofs.multiplier(free_[size_t(c)])) continue;
      for (int p = k.outer[size_t(c)]; p < k.outer[size_t(c) + 1]; ++p) {
        const int row = k.inner[size_t(p)];
        if (dofs.multiplier(free_[size_t(row)])) s[row] = std::max(s[row], diagonal[c]);
      }
    }
    for (int i = 0; i < n; ++i)
      if (dofs.multiplier(free_[size_t(i)]) && s[i] > 0) scale_[i] = s[i];
    for (int c = 0; c < n; ++c)
      for (int p = k.outer[size_t(c)]; p < k.outer[size_t(c) + 1]; ++p)
        k.values[size_t(p)] *= scale_[k.inner[size_t(p)]] * scale_[c];
  }
  // The diagonal scaling d_i = 1 / sqrt|s_ii| of the singularity test below.
  Eigen::VectorXd& d = d_;
  d.setOnes(n);
  for (int c = 0; c < n; ++c)
    for (int p = k.outer[size_t(c)]; p < k.outer[size_t(c) + 1]; ++p)
      if (k.inner[size_t(p)] == c && k.values[size_t(p)] != 0.0) d[c] = 1.0 / std::sqrt(std::abs(k.values[size_t(p)]));
  bool factored = false;
  if (!k.symbolic || k.outer != k.analysed_outer || k.inner != k.analysed_inner) {
    // A new pattern (the first factorization, or the model's structure changed).
    k.Clear();
    k.symbolic = klu_analyze(n, k.outer.data(), k.inner.data(), &k.common);
    if (!k.symbolic) return false;
    ++analysed_;
    k.analysed_outer = k.outer;
    k.analysed_inner = k.inner;
  } else if (k.numeric &&
             klu_refactor(k.outer.data(), k.inner.data(), k.values.data(), k.symbolic, k.numeric, &k.common)) {
    // The kept pivot order, while its pivots stay as good as the last full factorization's (the
    // ratio of the smallest to the largest, O(n); the pivot growth would cost a factorization).
    klu_rcond(k.symbolic, k.numeric, &k.common);
    factored = k.common.rcond > 1e-3 * k.rcond;
    if (factored) ++refactored_;
  }
  if (!factored) {
    if (!k.FactorAnew()) return false;
    ++full_;
  }
  // Singular or not is a property of the matrix scaled to unit diagonal, D S D (translations,
  // rotations and modal coordinates in any units alike): its inverse D^-1 S^-1 D^-1 is probed
  // with the factor on two fixed +-1 vectors (an O(nnz) estimate of ||(D S D)^-1||_1); singular
  // when ||D S D||_1 ||(D S D)^-1||_1 > 1e15. The solve itself stays unscaled.
  double norm = 0.0;
  for (int c = 0; c < n; ++c) {
    double column = 0.0;
    for (int p = k.outer[size_t(c)]; p < k.outer[size_t(c) + 1]; ++p)
      column += std::abs(d[k.inner[size_t(p)]] * k.values[size_t(p)] * d[c]);
    norm = std::max(norm, column);
  }
  double inverse = 0.0;
  for (int probe = 0; probe < 2; ++probe) {
    Eigen::VectorXd &x = x_, &y = y_;
    x.resize(n);
    y.resize(n);
    for (int i = 0; i < n; ++i) x[i] = ((i * (probe + 3) + probe) % 5 < 2) ? -1.0 : 1.0;
    y = d.cwiseInverse().asDiagonal() * x;
    klu_solve(k.symbolic, k.numeric, n, 1, y.data(), &k.common);
    y = d.cwiseInverse().asDiagonal() * y;
    if (!y.allFinite()) return false;
    inverse = std::max(inverse, y.lpNorm<1>() / x.lpNorm<1>());
  }
  valid_ = norm * inverse < 1e15;
  return valid_;
}

Eigen::VectorXd FreeSolver::Solve(const Eigen::VectorXd& r) const {
  Eigen::VectorXd d;
  Solve(r, d);
  return d;
}

void FreeSolver::Solve(const Eigen::VectorXd& r, Eigen::VectorXd& d) const {
  Eigen::VectorXd& rf = rf_;
  rf.resize(Eigen::Index(free_.size()));
  for (size_t i = 0; i < free_.size(); ++i) rf[i] = r[free_[i]] * scale_[Eigen::Index(i)];
  if (rf.size() > 0) klu_solve(klu_->symbolic, klu_->numeric, int(rf.size()), 1, rf.data(), &klu_->common);
  d.setZero(r.size());
  for (size_t i = 0; i < free_.size(); ++i) d[free_[i]] = rf[i] * scale_[Eigen::Index(i)];
}

Eigen::VectorXd SolveFree(const DofMap& dofs, const SystemMatrix& S, const Eigen::VectorXd& r) {
  FreeSolver solver;
  if (!solver.Factor(dofs, S)) return Eigen::VectorXd::Constant(r.size(), std::nan(""));
  return solver.Solve(r);
}

Eigen::MatrixXd DenseFreeMatrix(const DofMap& dofs, const SystemMatrix& S) {
  const std::vector<int>& free = dofs.solved();
  const int n = int(free.size());
  std::vector<int> position(S.rows(), -1);
  for (int i = 0; i < n; ++i) position[free[i]] = i;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  for (int col = 0; col < S.outerSize(); ++col)
    for (SystemMatrix::InnerIterator it(S, col); it; ++it)
      if (position[it.row()] >= 0 && position[col] >= 0) A(position[it.row()], position[col]) += it.value();
  return A;
}

std::string RoundOffToleranceWarning(double tolerance) {
  if (tolerance >= kRoundOffTolerance) return "";
  char buffer[200];
  std::snprintf(buffer, sizeof buffer,
                "analysis.tolerance %.3g is below the round-off floor of the residual; using %.0e", tolerance,
                kRoundOffTolerance);
  return buffer;
}

}  // namespace femb
