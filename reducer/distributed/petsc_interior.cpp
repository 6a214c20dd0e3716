#include "reducer/distributed/petsc_interior.h"

#include <mpi.h>
#include <petscmat.h>
#include <slepceps.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "reducer/linalg/shared_columns.h"
#include "reducer/progress.h"

namespace femb {
namespace {

// A PETSc call that failed (PetscReturnErrorHandler: no trace printed) as one exception.
void Check(PetscErrorCode code, const char* call) {
  if (code == 0) return;
  const char* text = nullptr;
  PetscErrorMessage(code, &text, nullptr);
  throw std::runtime_error(std::string("PETSc: ") + call + ": " + (text ? text : "error " + std::to_string(code)));
}
#define FEMB_PETSC(call) Check((call), #call)

// The rows this rank owns of an n-row matrix or vector (the columns it holds of the matrix
// factored, else PETSc's default split): `count` of them from `first`.
struct RowSplit {
  PetscInt n = 0, first = 0, count = 0;
};

RowSplit SplitRows(PetscInt n, const ColumnShare& held) {
  RowSplit s;
  s.n = n;
  PetscInt local = held.whole() ? PETSC_DECIDE : PetscInt(held.count), global = n, end = 0;
  FEMB_PETSC(PetscSplitOwnership(PETSC_COMM_WORLD, &local, &global));
  s.count = local;
  MPI_Scan(&local, &end, 1, MPIU_INT, MPI_SUM, PETSC_COMM_WORLD);
  s.first = end - local;
  return s;
}

// This rank's rows of the symmetric A (both triangles stored, so row j is column j; A replicated
// or shared by columns as `rows` are) as a distributed AIJ matrix.
Mat DistributedMatrix(const SparseMatrix& A, const RowSplit& rows) {
  std::vector<PetscInt> start(size_t(rows.count) + 1, 0), columns;
  std::vector<PetscScalar> values;
  for (PetscInt j = 0; j < rows.count; ++j) {
    for (SparseMatrix::InnerIterator it(A, int(rows.first + j)); it; ++it) {
      columns.push_back(PetscInt(it.row()));
      values.push_back(it.value());
    }
    start[size_t(j) + 1] = PetscInt(columns.size());
  }
  Mat M = nullptr;
  FEMB_PETSC(MatCreateMPIAIJWithArrays(PETSC_COMM_WORLD, rows.count, rows.count, rows.n, rows.n, start.data(),
                                       columns.data(), values.data(), &M));
  return M;
}

// This rank's rows of a vector as a column.
Eigen::VectorXd LocalRows(const RowSplit& rows, Vec v) {
  const PetscScalar* local = nullptr;
  FEMB_PETSC(VecGetArrayRead(v, &local));
  Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(local, rows.count);
  FEMB_PETSC(VecRestoreArrayRead(v, &local));
  return x;
}

void SetLocalRows(const RowSplit& rows, const Eigen::VectorXd& x, Vec v) {
  PetscScalar* local = nullptr;
  FEMB_PETSC(VecGetArrayWrite(v, &local));
  Eigen::Map<Eigen::VectorXd>(local, rows.count) = x;
  FEMB_PETSC(VecRestoreArrayWrite(v, &local));
}

// MUMPS' INFOG entries that count in millions when negative.
double Count(PetscInt infog) { return infog < 0 ? -1e6 * double(infog) : double(infog); }

// The shift-invert operator SLEPc applies (a PCSHELL in its KSP): the constrained solve on this
// rank's rows of the vector. Without constraints it is the factor's own solve.
struct ShellContext {
  const RowSplit* rows = nullptr;
  const BlockShiftInvertFn* solve = nullptr;
  Mat factor = nullptr;  ///< set: no constraints
  long applications = 0;
};

PetscErrorCode ApplyShiftInvert(PC pc, Vec x, Vec y) {
  ShellContext* context = nullptr;
  PetscCall(PCShellGetContext(pc, &context));
  ++context->applications;
  if (context->factor) return MatSolve(context->factor, x, y);
  try {
    SetLocalRows(*context->rows, (*context->solve)(LocalRows(*context->rows, x)).col(0), y);
  } catch (const std::exception&) {
    return PETSC_ERR_LIB;
  }
  return 0;
}

class PetscInterior : public InteriorSolver {
 public:
  ~PetscInterior() override {
    MatDestroy(&F_);
    MatDestroy(&A_);
  }

  FactorizationInfo Factorize(const SparseMatrix& A, const ColumnShare& held, double memory_limit_bytes) override {
    FactorizationInfo info;
    Stopwatch clock;
    // (the first collective step when nothing came before: a rank that failed before says so here)
    EnsureStartAgreed();
    rows_ = SplitRows(PetscInt(A.rows()), held);
    held_ = held;
    A_ = DistributedMatrix(A, rows_);
    factored_ = &A;
    FEMB_PETSC(MatSetOption(A_, MAT_SPD, PETSC_TRUE));
    // MUMPS' workspace is its analysis' estimate plus ICNTL(14) percent; on several ranks its
    // dynamic scheduling can need more (INFOG(1) -8, -9, -17, -20: an all-RBE3 crank on 4 ranks
    // failed so in one run of ten at the default 20%), and the factorization then starts again
    // from the analysis with three times as much (PETSc does not repeat a failed factorization).
    info.analyze_seconds = clock.Seconds();  // (the distributed matrix, then the analyses)
    PetscInt status = 0, percent = 20;
    for (int attempt = 0;; ++attempt, percent *= 3) {
      MatFactorInfo factor_info;
      if (!Analyze(percent, memory_limit_bytes, &factor_info, &info)) return info;
      clock.Restart();
      FEMB_PETSC(MatCholeskyFactorNumeric(F_, A_, &factor_info));
      info.numeric_seconds = clock.Seconds();
      FEMB_PETSC(MatMumpsGetInfog(F_, 1, &status));
      if (!(status == -8 || status == -9 || status == -17 || status == -20) || attempt == 2) break;
    }
    MatFactorError error = MAT_FACTOR_NOERROR;
    FEMB_PETSC(MatFactorGetError(F_, &error));
    if (error != MAT_FACTOR_NOERROR || status < 0) {
      info.message = status == -10 ? std::string("MUMPS found a zero or negative pivot (INFOG(1) = -10)")
                     : status == -13
                         ? std::string("MUMPS could not allocate its workspace (INFOG(1) = -13): out of memory")
                         : Format("MUMPS stopped with INFOG(1) = %.0f", double(status)) +
                               Format(" (its workspace %.0f%% over the analysis' estimate)", double(percent));
      info.resource_failure = status != -10;
      return info;
    }
    PetscReal flops = 0;
    FEMB_PETSC(MatMumpsGetRinfog(F_, 3, &flops));
    info.flops = flops;
    PetscInt entries = 0;
    FEMB_PETSC(MatMumpsGetInfog(F_, 29, &entries));  // the factor's entries
    info.factor_entries = Count(entries);
    info.factor_bytes = 8.0 * info.factor_entries;
    info.ok = true;
    return info;
  }

  // MUMPS' analysis of A_ (sequential, METIS' nested dissection) into a new F_ whose workspace
  // is the estimate plus `percent`; the estimates into `info`. False (info->too_big) when the
  // largest rank's estimate exceeds the limit (the smallest of the ranks' limits).
  bool Analyze(PetscInt percent, double memory_limit_bytes, MatFactorInfo* factor_info, FactorizationInfo* info) {
    Stopwatch clock;
    MatDestroy(&F_);
    FEMB_PETSC(MatGetFactor(A_, MATSOLVERMUMPS, MAT_FACTOR_CHOLESKY, &F_));
    FEMB_PETSC(MatMumpsSetIcntl(F_, 28, 1));  // sequential analysis ...
    FEMB_PETSC(MatMumpsSetIcntl(F_, 7, 5));   // ... with METIS' nested dissection
    FEMB_PETSC(MatMumpsSetIcntl(F_, 14, percent));
    FEMB_PETSC(MatFactorInfoInitialize(factor_info));
    FEMB_PETSC(MatCholeskyFactorSymbolic(F_, A_, nullptr, factor_info));
    info->analyze_seconds += clock.Seconds();
    PetscInt largest_mb = 0, total_mb = 0, entries = 0;
    FEMB_PETSC(MatMumpsGetInfog(F_, 16, &largest_mb));  // estimated memory, largest rank (MB)
    FEMB_PETSC(MatMumpsGetInfog(F_, 17, &total_mb));    // ... all ranks
    FEMB_PETSC(MatMumpsGetInfog(F_, 20, &entries));     // estimated entries of the factor
    int size = 1;
    MPI_Comm_size(PETSC_COMM_WORLD, &size);
    info->ordering = Format("metis; MUMPS on %.0f ranks, estimated %.3g GB on the largest, %.3g GB in all", size,
                            double(largest_mb) / 1e3, double(total_mb) / 1e3) +
                     (percent > 20 ? Format(", workspace +%.0f%%", double(percent)) : "");
    info->factor_entries = Count(entries);
    info->factor_bytes = 8.0 * info->factor_entries;
    MPI_Allreduce(MPI_IN_PLACE, &memory_limit_bytes, 1, MPI_DOUBLE, MPI_MIN, PETSC_COMM_WORLD);
    if (memory_limit_bytes > 0 && 1e6 * double(largest_mb) > memory_limit_bytes) {
      info->too_big = true;
      info->message = Format("MUMPS' factorization of K_ii needs %.3g GB on its largest rank (%.3g GB in all)",
                             double(largest_mb) / 1e3, double(total_mb) / 1e3) +
                      Format(", more than the %.3g GB a rank may use", memory_limit_bytes / 1e9);
      return false;
    }
    return true;
  }

  Eigen::MatrixXd Solve(const Eigen::MatrixXd& B) override {
    const int k = int(B.cols());
    solves_ += k;
    if (k == 0) return Eigen::MatrixXd(rows_.count, 0);
    if (B.rows() != rows_.count) throw std::logic_error("a solve given other rows than this rank's");
    Mat Bm = nullptr, Xm = nullptr;
    FEMB_PETSC(MatCreateDense(PETSC_COMM_WORLD, rows_.count, PETSC_DECIDE, rows_.n, k, nullptr, &Bm));
    PetscScalar* b = nullptr;
    PetscInt lda = 0;
    FEMB_PETSC(MatDenseGetLDA(Bm, &lda));
    FEMB_PETSC(MatDenseGetArrayWrite(Bm, &b));
    for (int c = 0; c < k; ++c)
      for (PetscInt i = 0; i < rows_.count; ++i) b[c * lda + i] = B(i, c);
    FEMB_PETSC(MatDenseRestoreArrayWrite(Bm, &b));
    FEMB_PETSC(MatAssemblyBegin(Bm, MAT_FINAL_ASSEMBLY));
    FEMB_PETSC(MatAssemblyEnd(Bm, MAT_FINAL_ASSEMBLY));
    FEMB_PETSC(MatDuplicate(Bm, MAT_DO_NOT_COPY_VALUES, &Xm));
    FEMB_PETSC(MatMatSolve(F_, Bm, Xm));
    const PetscScalar* x = nullptr;
    FEMB_PETSC(MatDenseGetLDA(Xm, &lda));
    FEMB_PETSC(MatDenseGetArrayRead(Xm, &x));
    Eigen::MatrixXd X(rows_.count, k);
    for (int c = 0; c < k; ++c)
      for (PetscInt i = 0; i < rows_.count; ++i) X(i, c) = x[c * lda + i];
    FEMB_PETSC(MatDenseRestoreArrayRead(Xm, &x));
    MatDestroy(&Xm);
    MatDestroy(&Bm);
    return X;
  }

  long solves() const override { return solves_; }

  std::optional<EigenResult> Eigenpairs(const SparseMatrix& K, const SparseMatrix& M, int nev, double tol,
                                        const BlockShiftInvertFn& solve, bool plain) override;

  std::string EigenDetail() const override { return detail_; }

 private:
  RowSplit rows_;
  ColumnShare held_;  ///< the columns this rank holds of the matrices given
  Mat A_ = nullptr, F_ = nullptr;
  const SparseMatrix* factored_ = nullptr;  ///< the matrix A_ holds (K_ii itself unless augmented)
  long solves_ = 0;
  std::string detail_;
};

// SLEPc's Krylov-Schur on K x = lambda M x (generalized Hermitian: M inner product) with
// shift-and-invert at 0; the inversion is the constrained solve on this factor (a PCSHELL in a
// preonly KSP), so no second factor is made. The start vector is the solve of M times ones (in
// the constrained space, and the same for any number of ranks). Eigenvectors M-normalized,
// ascending.
std::optional<EigenResult> PetscInterior::Eigenpairs(const SparseMatrix& K, const SparseMatrix& M, int nev, double tol,
                                                     const BlockShiftInvertFn& solve, bool plain) {
  EigenResult r;
  if (nev == 0) {
    r.ok = true;
    return r;
  }
  // K_ii is distributed already when it is the matrix factored (not augmented): shared, not copied.
  Mat Kd = &K == factored_ ? A_ : DistributedMatrix(K, rows_), Md = DistributedMatrix(M, rows_);
  if (Kd == A_) FEMB_PETSC(PetscObjectReference(reinterpret_cast<PetscObject>(A_)));
  EPS eps = nullptr;
  FEMB_PETSC(EPSCreate(PETSC_COMM_WORLD, &eps));
  FEMB_PETSC(EPSSetOperators(eps, Kd, Md));
  FEMB_PETSC(EPSSetProblemType(eps, EPS_GHEP));
  FEMB_PETSC(EPSSetType(eps, EPSKRYLOVSCHUR));
  ST st = nullptr;
  FEMB_PETSC(EPSGetST(eps, &st));
  FEMB_PETSC(STSetType(st, STSINVERT));
  FEMB_PETSC(EPSSetTarget(eps, 0.0));
  FEMB_PETSC(EPSSetWhichEigenpairs(eps, EPS_TARGET_MAGNITUDE));
  KSP ksp = nullptr;
  FEMB_PETSC(STGetKSP(st, &ksp));
  FEMB_PETSC(KSPSetType(ksp, KSPPREONLY));
  PC pc = nullptr;
  FEMB_PETSC(KSPGetPC(ksp, &pc));
  FEMB_PETSC(PCSetType(pc, PCSHELL));
  ShellContext context{&rows_, &solve, plain ? F_ : nullptr, 0};
  FEMB_PETSC(PCShellSetContext(pc, &context));
  FEMB_PETSC(PCShellSetApply(pc, ApplyShiftInvert));
  FEMB_PETSC(EPSSetDimensions(eps, nev, PETSC_DEFAULT, PETSC_DEFAULT));
  FEMB_PETSC(EPSSetTolerances(eps, tol, 1000));
  Vec start = nullptr, x = nullptr;
  FEMB_PETSC(MatCreateVecs(Kd, &start, &x));
  const Eigen::MatrixXd ones = Eigen::MatrixXd::Ones(rows_.count, 1);
  SetLocalRows(rows_, solve(SharedTimesRows(M, ones, held_)).col(0), start);
  FEMB_PETSC(EPSSetInitialSpace(eps, 1, &start));
  FEMB_PETSC(EPSSolve(eps));
  PetscInt converged = 0, iterations = 0;
  FEMB_PETSC(EPSGetConverged(eps, &converged));
  FEMB_PETSC(EPSGetIterationNumber(eps, &iterations));
  if (converged < nev) {
    r.message = Format("SLEPc's Krylov-Schur converged %.0f of %.0f eigenpairs in %.0f restarts", double(converged),
                       nev, double(iterations));
  } else {
    r.lambda.resize(nev);
    r.vectors.resize(rows_.count, nev);
    Vec Mx = nullptr;
    FEMB_PETSC(VecDuplicate(x, &Mx));
    for (int i = 0; i < nev; ++i) {
      PetscScalar lambda = 0, norm2 = 0;
      FEMB_PETSC(EPSGetEigenpair(eps, i, &lambda, nullptr, x, nullptr));
      FEMB_PETSC(MatMult(Md, x, Mx));
      FEMB_PETSC(VecDot(Mx, x, &norm2));
      r.lambda[i] = lambda;
      r.vectors.col(i) = LocalRows(rows_, x) / std::sqrt(norm2);
    }
    VecDestroy(&Mx);
    r.ok = true;
  }
  r.linear_solves = context.applications + 1;
  if (plain) solves_ += context.applications;  // (the constrained solve counts its own)
  detail_ = Format("SLEPc Krylov-Schur, shift-and-invert on the MUMPS factor, %.0f restarts", double(iterations));
  VecDestroy(&x);
  VecDestroy(&start);
  EPSDestroy(&eps);
  MatDestroy(&Md);
  MatDestroy(&Kd);
  return r;
}

}  // namespace

std::unique_ptr<InteriorSolver> MakePetscInterior() { return std::make_unique<PetscInterior>(); }

}  // namespace femb
