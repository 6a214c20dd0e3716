// femb-reduce on MPI ranks (mpirun -np N femb-reduce PART.yaml): MPI, PETSc and SLEPc started
// and ended for the process, the ranks' collectives registered (shared_columns.h). Every rank runs
// the same reduction on the mesh rank 0 made and partitioned (solid_ranks.h), holding its part's
// columns of K and M; the interior's factor and eigen solve are distributed (petsc_interior.h);
// rank 0 alone prints and writes the file.
#pragma once

#include <utility>

namespace femb {

/// SlepcInitialize (which starts MPI and PETSc) on construction, SlepcFinalize on destruction;
/// registers the petsc interior solver (linalg/interior_solver.h) and gives each rank one BLAS
/// thread when several ranks share the machine's cores.
class MpiRanks {
 public:
  MpiRanks();
  ~MpiRanks();
  MpiRanks(const MpiRanks&) = delete;
  MpiRanks& operator=(const MpiRanks&) = delete;
  int rank() const { return rank_; }
  int size() const { return size_; }
  /// The peak resident memory of the largest rank and of all ranks, bytes (collective).
  std::pair<double, double> PeakMemory() const;
  /// Ends every rank with `code` (a failure on some ranks only, which the others would wait on).
  [[noreturn]] void Abort(int code) const;

 private:
  int rank_ = 0, size_ = 1;
};

}  // namespace femb
