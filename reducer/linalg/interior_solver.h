// The linear algebra of a Craig-Bampton reduction's interior: one factor of K_ii (or of the
// augmented matrix when every interface is distributing) with its solves, and optionally its own
// eigen solver. CHOLMOD (sparse_cholesky.h) on one process is the default; a distributed solver
// (MUMPS and SLEPc over MPI, reducer/distributed/) is registered by femb-reduce when it runs on
// MPI ranks. Each rank of a distributed run gives and receives its rows of the right-hand sides
// and solutions (the rows of the columns it holds of the matrix factored: the reduction's dense
// blocks divide by the number of ranks while the factor lives); their products with the matrices,
// which the ranks share by columns, and with each other are summed (shared_columns.h).
#pragma once

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "formats/kinds.h"
#include "reducer/fe/fe_model.h"
#include "reducer/linalg/generalized_eigen.h"
#include "reducer/linalg/sparse_cholesky.h"

namespace femb {

class InteriorSolver {
 public:
  virtual ~InteriorSolver() = default;
  /// Factorizes the symmetric positive definite A (both triangles stored) of which this process
  /// holds the columns `held` (all on one process; a rank's share when A is shared by columns,
  /// shared_columns.h: only a distributed solver takes a share). With `memory_limit_bytes` > 0,
  /// refuses (info.too_big) before the numeric factorization when the factor (a distributed
  /// solver: its largest rank's share) would not fit.
  virtual FactorizationInfo Factorize(const SparseMatrix& A, const ColumnShare& held, double memory_limit_bytes) = 0;
  /// X = A^-1 B for a block of right-hand sides, B and X this rank's rows (HeldRows of the share
  /// given to Factorize; all of them on one process). Precondition: Factorize succeeded.
  virtual Eigen::MatrixXd Solve(const Eigen::MatrixXd& B) = 0;
  /// Right-hand sides solved so far.
  virtual long solves() const = 0;
  /// The lowest `nev` eigenpairs of K x = lambda M x (K and M held as A was) on the space the constrained shift-invert
  /// `solve` maps into (it applies the factor, on this rank's rows as Solve; the eigenvectors are
  /// this rank's rows too), residual tolerance `tol` relative to the
  /// eigenvalue; empty when this solver has no eigen solver of its own (femb's block Lanczos then
  /// runs on `solve`). `plain`: `solve` is the factor's own solve (no constraints), which the
  /// solver may then apply in its own way.
  virtual std::optional<EigenResult> Eigenpairs(const SparseMatrix& K, const SparseMatrix& M, int nev, double tol,
                                                const BlockShiftInvertFn& solve, bool plain) {
    (void)K, (void)M, (void)nev, (void)tol, (void)solve, (void)plain;
    return std::nullopt;
  }
  /// How the eigen solve ran, for the progress line ("" when Eigenpairs has none).
  virtual std::string EigenDetail() const { return ""; }
};

/// What the ranks of a distributed run agree on (AgreeOnStart).
struct RankAgreement {
  int code = 0;
  int first_failed = -1;
};

/// Makes the solver of a given kind. Throws InputError (naming `where`) for petsc when no
/// distributed solver is registered in this program.
std::unique_ptr<InteriorSolver> MakeInteriorSolver(ReductionSolver kind, const std::string& where = "");

/// Throws the InputError of MakeInteriorSolver (naming `where`) when the kind cannot be made here:
/// checked before the work.
void RequireInteriorSolver(ReductionSolver kind, const std::string& where);

/// The distributed solver's maker and the number of MPI ranks, set by a program that runs on MPI
/// (femb-reduce); ranks() is 1 until then.
/// `agree` (AgreeOnStart's collective), this process's `rank` and the number of ranks on its
/// machine with them.
void RegisterDistributedSolver(std::function<std::unique_ptr<InteriorSolver>()> make, int ranks,
                               std::function<RankAgreement(int)> agree = nullptr, int rank = 0,
                               int ranks_on_machine = 1);
/// The ranks of a distributed run on this process's machine (1 on one process): they share its
/// memory.
int RanksOnThisMachine();
int DistributedRanks();

/// The number of ranks an MPI launcher started (OpenMPI's OMPI_COMM_WORLD_SIZE, MPICH's
/// PMI_SIZE), 0 when the process was not started by one.
int LaunchedRanks();
/// This process's rank by the launcher's environment (0 when not launched by one): known before
/// MPI starts, so that only rank 0 reports an input error.
int LaunchedRank();

/// Whether the ranks of a distributed run all reached the distributed work: each rank calls this
/// once, with 0 at the solver's first step or with its exit code where it failed before (then the
/// others stop with that code instead of waiting for it). The largest code and the lowest rank that
/// failed (-1: none); {code, -1 or 0} on one process.
RankAgreement AgreeOnStart(int code);
/// True once AgreeOnStart ran (a failure after it is every rank's, or one rank's that ends all).
bool StartAgreed();
/// AgreeOnStart(0) unless it ran: the first collective of a distributed run (its solver's first
/// step, or the first sum over the ranks). Throws RankFailure with the code of a rank that failed
/// before it.
void EnsureStartAgreed();
/// This process's MPI rank (0 on one process).
int DistributedRank();

/// A distributed run's failure that every rank meets together (another rank failed before the
/// distributed work, or the ranks built different models): said by one rank, the same exit code
/// on all.
class RankFailure : public std::runtime_error {
 public:
  RankFailure(int code, const std::string& what, bool said_here)
      : std::runtime_error(what), code_(code), said_here_(said_here) {}
  int code() const { return code_; }
  bool said_here() const { return said_here_; }

 private:
  int code_;
  bool said_here_;
};

/// The solver a part asks for: its reduction.solver, or cholmod on one process and petsc on
/// more than one.
ReductionSolver ResolvedSolver(const std::optional<ReductionSolver>& given);

}  // namespace femb
