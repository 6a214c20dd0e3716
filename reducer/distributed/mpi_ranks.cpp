#include "reducer/distributed/mpi_ranks.h"

#include <dlfcn.h>
#include <mpi.h>
#include <slepcsys.h>

#include <algorithm>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "reducer/distributed/petsc_interior.h"
#include "reducer/linalg/interior_solver.h"
#include "reducer/linalg/shared_columns.h"
#include "reducer/linalg/sparse_cholesky.h"

namespace femb {
namespace {

// The collectives of the ranks sharing the model's columns (shared_columns.h), each after the
// ranks agreed to start. Large buffers go in pieces below MPI's int counts.
void SumOverAll(double* data, long count) {
  EnsureStartAgreed();
  constexpr long kPiece = 1L << 28;
  for (long at = 0; at < count; at += kPiece) {
    MPI_Allreduce(MPI_IN_PLACE, data + at, int(std::min(kPiece, count - at)), MPI_DOUBLE, MPI_SUM, PETSC_COMM_WORLD);
  }
}

std::vector<std::string> GatherAll(const std::string& mine) {
  EnsureStartAgreed();
  int size = 1;
  MPI_Comm_size(PETSC_COMM_WORLD, &size);
  if (mine.size() > size_t(std::numeric_limits<int>::max())) {
    throw std::runtime_error("a rank's share to gather exceeds 2 GB");
  }
  const int bytes = int(mine.size());
  std::vector<int> counts(static_cast<size_t>(size)), displacements(static_cast<size_t>(size), 0);
  MPI_Allgather(&bytes, 1, MPI_INT, counts.data(), 1, MPI_INT, PETSC_COMM_WORLD);
  long total = 0;
  for (int r = 0; r < size; ++r) {
    displacements[size_t(r)] = int(total);  // (meaningful once the total is checked below)
    total += counts[size_t(r)];
  }
  if (total > std::numeric_limits<int>::max()) throw std::runtime_error("the ranks' shares to gather exceed 2 GB");
  std::string all(size_t(total), '\0');
  MPI_Allgatherv(mine.data(), bytes, MPI_BYTE, all.data(), counts.data(), displacements.data(), MPI_BYTE,
                 PETSC_COMM_WORLD);
  std::vector<std::string> out;
  for (int r = 0; r < size; ++r) out.push_back(all.substr(size_t(displacements[size_t(r)]), size_t(counts[size_t(r)])));
  return out;
}

std::vector<std::string> ExchangeAll(const std::vector<std::string>& to) {
  EnsureStartAgreed();
  int size = 1;
  MPI_Comm_size(PETSC_COMM_WORLD, &size);
  if (to.size() != size_t(size)) throw std::logic_error("an exchange with other than one message per rank");
  const size_t ranks = static_cast<size_t>(size);
  std::vector<int> send_counts(ranks), receive_counts(ranks);
  std::vector<int> send_at(ranks, 0), receive_at(ranks, 0);
  long send_total = 0, receive_total = 0;
  for (int r = 0; r < size; ++r) {
    send_counts[size_t(r)] = int(to[size_t(r)].size());
    send_at[size_t(r)] = int(send_total);
    send_total += long(to[size_t(r)].size());
  }
  MPI_Alltoall(send_counts.data(), 1, MPI_INT, receive_counts.data(), 1, MPI_INT, PETSC_COMM_WORLD);
  for (int r = 0; r < size; ++r) {
    receive_at[size_t(r)] = int(receive_total);
    receive_total += receive_counts[size_t(r)];
  }
  // (the check after the counts' exchange, so that every rank takes part in it)
  int too_big = send_total > std::numeric_limits<int>::max() || receive_total > std::numeric_limits<int>::max();
  MPI_Allreduce(MPI_IN_PLACE, &too_big, 1, MPI_INT, MPI_MAX, PETSC_COMM_WORLD);
  if (too_big) throw std::runtime_error("a rank's rows to exchange exceed 2 GB");
  std::string sent;
  for (const std::string& bytes : to) sent += bytes;
  std::string received(size_t(receive_total), '\0');
  MPI_Alltoallv(sent.data(), send_counts.data(), send_at.data(), MPI_BYTE, received.data(), receive_counts.data(),
                receive_at.data(), MPI_BYTE, PETSC_COMM_WORLD);
  std::vector<std::string> from;
  for (int r = 0; r < size; ++r)
    from.push_back(received.substr(size_t(receive_at[size_t(r)]), size_t(receive_counts[size_t(r)])));
  return from;
}

}  // namespace

MpiRanks::MpiRanks() {
  // PETSc's signal handlers would print pages for a SIGINT; its error handler returns the code,
  // which the solver turns into one line (petsc_interior.cpp).
  PetscOptionsSetValue(nullptr, "-no_signal_handler", "true");
  if (SlepcInitializeNoArguments() != 0) throw std::runtime_error("SLEPc (MPI, PETSc) did not start");
  PetscPushErrorHandler(PetscReturnErrorHandler, nullptr);
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank_);
  MPI_Comm_size(PETSC_COMM_WORLD, &size_);
  // Ranks on one machine share its cores: one BLAS thread each (OpenBLAS, looked up at run time:
  // libblas.so.3 may be another BLAS).
  MPI_Comm node;
  MPI_Comm_split_type(PETSC_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node);
  int on_node = 1;
  MPI_Comm_size(node, &on_node);
  MPI_Comm_free(&node);
  if (on_node > 1) {
    using SetThreads = void (*)(int);
    if (auto set = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"))) {
      const int cores = int(std::thread::hardware_concurrency());
      set(std::max(1, cores / on_node));
    }
  }
  const int size = size_, rank = rank_;
  const auto agree = [size, rank](int code) {
    int mine[2] = {code, code != 0 ? rank : size}, all[2] = {0, 0};
    MPI_Allreduce(&mine[0], &all[0], 1, MPI_INT, MPI_MAX, PETSC_COMM_WORLD);
    MPI_Allreduce(&mine[1], &all[1], 1, MPI_INT, MPI_MIN, PETSC_COMM_WORLD);
    return RankAgreement{all[0], all[1] < size ? all[1] : -1};
  };
  RegisterDistributedSolver([] { return MakePetscInterior(); }, size_, agree, rank_, on_node);
  if (size_ > 1) RegisterRankCollectives(SumOverAll, GatherAll, ExchangeAll);
}

MpiRanks::~MpiRanks() {
  RegisterRankCollectives(nullptr, nullptr);
  RegisterDistributedSolver(nullptr, 1);
  SlepcFinalize();
}

std::pair<double, double> MpiRanks::PeakMemory() const {
  const double mine = PeakResidentBytes();
  double largest = 0.0, all = 0.0;
  MPI_Allreduce(&mine, &largest, 1, MPI_DOUBLE, MPI_MAX, PETSC_COMM_WORLD);
  MPI_Allreduce(&mine, &all, 1, MPI_DOUBLE, MPI_SUM, PETSC_COMM_WORLD);
  return {largest, all};
}

void MpiRanks::Abort(int code) const {
  MPI_Abort(PETSC_COMM_WORLD, code);
  std::exit(code);
}

}  // namespace femb
