#include "reducer/linalg/interior_solver.h"

#include <cstdlib>
#include <stdexcept>

#include "formats/input_error.h"

namespace femb {
namespace {

// CHOLMOD's supernodal factor (one process; BLAS threads inside).
class CholmodInterior : public InteriorSolver {
 public:
  FactorizationInfo Factorize(const SparseMatrix& A, const ColumnShare& held, double memory_limit_bytes) override {
    if (!held.whole()) throw std::logic_error("CHOLMOD factors a whole matrix, not a rank's share of its columns");
    return factor_.Compute(A, memory_limit_bytes);
  }
  Eigen::MatrixXd Solve(const Eigen::MatrixXd& B) override { return factor_.Solve(B); }
  long solves() const override { return factor_.solves(); }

 private:
  SparseCholesky factor_;
};

int EnvironmentInteger(const char* a, const char* b, int otherwise) {
  for (const char* name : {a, b}) {
    if (const char* v = std::getenv(name)) return std::atoi(v);
  }
  return otherwise;
}

struct Registry {
  std::function<std::unique_ptr<InteriorSolver>()> make;
  int ranks = 1, rank = 0, on_machine = 1;
  std::function<RankAgreement(int)> agree;
  bool agreed = false;
};

Registry& TheRegistry() {
  static Registry registry;
  return registry;
}

}  // namespace

void RequireInteriorSolver(ReductionSolver kind, const std::string& where) {
  if (kind == ReductionSolver::kPetsc && !TheRegistry().make) {
    throw InputError((where.empty() ? std::string("reduction.solver") : where) +
                     ": the petsc solver (MUMPS and SLEPc over MPI) runs in femb-reduce built with PETSc and SLEPc "
                     "(scripts/setup.sh installs them): start it as mpirun -np N femb-reduce PART.yaml");
  }
}

std::unique_ptr<InteriorSolver> MakeInteriorSolver(ReductionSolver kind, const std::string& where) {
  if (kind == ReductionSolver::kCholmod) return std::make_unique<CholmodInterior>();
  RequireInteriorSolver(kind, where);
  return TheRegistry().make();
}

void RegisterDistributedSolver(std::function<std::unique_ptr<InteriorSolver>()> make, int ranks,
                               std::function<RankAgreement(int)> agree, int rank, int ranks_on_machine) {
  Registry& r = TheRegistry();
  r.on_machine = ranks_on_machine;
  r.make = std::move(make);
  r.ranks = ranks;
  r.rank = rank;
  r.agree = std::move(agree);
  r.agreed = false;
}

RankAgreement AgreeOnStart(int code) {
  Registry& r = TheRegistry();
  r.agreed = true;
  if (r.agree) return r.agree(code);
  return {code, code != 0 ? 0 : -1};
}

bool StartAgreed() { return TheRegistry().agreed; }

void EnsureStartAgreed() {
  if (StartAgreed()) return;
  const RankAgreement start = AgreeOnStart(0);
  if (start.code != 0) throw RankFailure(start.code, "another rank failed", false);
}

int DistributedRank() { return TheRegistry().rank; }

int RanksOnThisMachine() { return TheRegistry().on_machine; }

int DistributedRanks() { return TheRegistry().ranks; }

int LaunchedRanks() { return EnvironmentInteger("OMPI_COMM_WORLD_SIZE", "PMI_SIZE", 0); }

int LaunchedRank() { return EnvironmentInteger("OMPI_COMM_WORLD_RANK", "PMI_RANK", 0); }

ReductionSolver ResolvedSolver(const std::optional<ReductionSolver>& given) {
  if (given) return *given;
  return DistributedRanks() > 1 ? ReductionSolver::kPetsc : ReductionSolver::kCholmod;
}

}  // namespace femb
