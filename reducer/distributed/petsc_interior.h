// The interior solver of a reduction on MPI ranks (reduction.solver: petsc): the factor of K_ii
// is MUMPS' distributed Cholesky (LDL^T of a symmetric positive definite matrix, METIS ordering,
// each rank holding its share of the factor), the solves are MUMPS' multi-right-hand-side solves,
// and the fixed-interface modes come from SLEPc's Krylov-Schur with shift-and-invert at 0 on that
// same factor (the interfaces' constraints applied in the shift-invert operator, as on one
// process). K_ii and M_ii are distributed by rows: each rank gives the columns it holds of them
// (shared_columns.h; the symmetric matrices' rows), or PETSc's default split of a replicated one;
// right-hand sides, solutions and eigenvectors are this rank's rows of them, as PETSc holds them.
#pragma once

#include <memory>

#include "reducer/linalg/interior_solver.h"

namespace femb {

/// Needs a running MpiRanks (mpi_ranks.h).
std::unique_ptr<InteriorSolver> MakePetscInterior();

}  // namespace femb
