// The linear solver of the iteration matrix on the coordinates solved for (KLU).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "solver/assembly/system_model.h"

namespace femb {

/// Solves S d = r on the coordinates that are not prescribed (prescribed ones: d = 0) with
/// FreeSolver.
Eigen::VectorXd SolveFree(const DofMap& dofs, const SystemMatrix& S, const Eigen::VectorXd& r);

/// The sparse LU factor of S on the coordinates solved for, kept for several solves (Jacobian
/// reuse): Factor once, Solve many times. KLU (SuiteSparse; Davis & Palamadai Natarajan 2010,
/// made for the repeated factorizations of one sparsity pattern in circuit simulation): its
/// ordering (block triangular form, then AMD on each block) is computed once per pattern, and a
/// factorization with the same pattern reuses the analysis and, while its pivots stay good
/// (the ratio of its smallest to its largest pivot within 1e-3 of the last full factorization's), the
/// pivot order (klu_refactor); otherwise it pivots anew (klu_factor). Factor returns false when
/// the matrix is singular: a zero pivot or a condition estimate of the matrix scaled to unit
/// diagonal (D S D) above 1e15.
/// What a FreeSolver keeps from one factorization to the next: the pattern it analysed, the
/// (scaled) values of the last factorization that chose its pivots, and its counts. Restored, a
/// solver chooses the same pivots and refactors as the one it was saved from (a resumed run).
struct FactorMemory {
  std::vector<int> outer, inner;
  std::vector<double> pivot_values;
  long analysed = 0, full = 0, refactored = 0;
};

class FreeSolver {
 public:
  FreeSolver();
  ~FreeSolver();
  FreeSolver(const FreeSolver&) = delete;
  FreeSolver& operator=(const FreeSolver&) = delete;
  bool Factor(const DofMap& dofs, const SystemMatrix& S);
  Eigen::VectorXd Solve(const Eigen::VectorXd& r) const;
  /// The same into `d` (its storage reused: no allocation once sized).
  void Solve(const Eigen::VectorXd& r, Eigen::VectorXd& d) const;
  bool valid() const { return valid_; }
  void Invalidate() { valid_ = false; }
  /// Sparsity patterns analysed, factorizations that pivoted anew (klu_factor), and those that
  /// reused the pivot order (klu_refactor).
  long analyses() const { return analysed_; }
  long full_factorizations() const { return full_; }
  long refactorizations() const { return refactored_; }
  /// The pivot order's source (FactorMemory). Restore leaves no valid factor: the next Factor
  /// refactors with the restored pivots as the saved solver would have.
  void Save(FactorMemory& memory) const;
  bool Restore(const FactorMemory& memory);

 private:
  struct Klu;
  std::unique_ptr<Klu> klu_;
  std::vector<int> free_, position_;
  Eigen::VectorXd scale_;  ///< per free unknown: 1, or a multiplier's scaling (see Factor)
  // Scratch of Factor and Solve, kept so that neither allocates once sized.
  Eigen::VectorXd diagonal_, multiplier_scale_, d_, x_, y_;
  mutable Eigen::VectorXd rf_;
  bool valid_ = false;
  long analysed_ = 0, full_ = 0, refactored_ = 0;
};
/// S restricted to the coordinates solved for, dense (n_free x n_free).
Eigen::MatrixXd DenseFreeMatrix(const DofMap& dofs, const SystemMatrix& S);

/// The message an analysis gives once when asked for a Newton tolerance below kRoundOffTolerance
/// (empty when the tolerance is fine).
std::string RoundOffToleranceWarning(double tolerance);

}  // namespace femb
