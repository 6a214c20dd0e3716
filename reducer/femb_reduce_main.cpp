// femb-reduce: a part file in, a Craig-Bampton superelement file out.
#include <malloc.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "formats/command_line.h"
#include "formats/input_error.h"
#include "formats/part_file.h"
#include "reducer/fe/imported_model.h"
#include "reducer/linalg/interior_solver.h"
#include "reducer/linalg/sparse_cholesky.h"
#include "reducer/reduce_file.h"
#ifdef FEMB_WITH_PETSC
#include "reducer/distributed/mpi_ranks.h"
#endif

namespace {

// Large blocks in their own mappings, given back to the system when freed. SuperLU_DIST, which
// PETSc links, turns that off when it loads (mallopt(M_MMAP_MAX, 0)): the reduction's large blocks
// then stay in the heap once freed, and its peak memory grows by a fifth (1.17 GB against 0.96 GB
// on the 1e5-DOF crank). Set back before any work, with glibc's own limits; a fixed threshold (the
// largest glibc's dynamic one reaches, 32 MiB on 64 bits), since setting any of them stops glibc
// from moving it, and a threshold left at 128 KiB maps and unmaps every block of solves anew.
void RestoreLargeBlockMappings() {
  mallopt(M_MMAP_MAX, 65536);
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 64 << 20);
}

constexpr const char* kUsage =
    R"(usage: femb-reduce PART.yaml [-o OUT.h5] [--full-modes K] [--set key=value]... [--quiet]
       femb-reduce PART.yaml --export-matrices DIR [--matrix-format F]

Reduces a part (beam polyline; solid: gmsh geometry, built-in shape or mesh file; or matrices
imported from another FE code; see formats/PART_FORMAT.md) to a Craig-Bampton superelement file
(HDF5; see formats/SUPERELEMENT_FORMAT.md).

options:
  -o, --output OUT.h5   output file (default: <part name>.h5 in the current folder). Written to a
                        temporary name and renamed, so it is never half-written.
  --full-modes K        also compute the K lowest nonzero free-free frequencies of the unreduced
                        model (plus the 6 rigid-body ones) and store them for comparison
                        (same as --set reduction.full_modes=K)
  --set key=value       override a part-file key, e.g. --set reduction.internal_modes=8
                        --set reduction.floating_frame=mean_axes (repeatable)
  --export-matrices DIR instead of reducing: write the part's assembled stiffness and mass (before
                        any interface coupling: solids 3 DOFs per mesh node, beams 6) and its mesh
                        (DIR/NAME.inp, node labels = matrix node numbers, named node sets), for
                        another FE code or for a part file of type 'imported'
  --matrix-format F     calculix (NAME.sti/.mas/.dof, default), abaqus (NAME_STIF1.mtx,
                        NAME_MASS1.mtx: node, dof, node, dof, value), abaqus_coordinate (the same
                        files as row, column, value) or matrix_market (NAME_K.mtx, NAME_M.mtx,
                        NAME_dofs.csv). The abaqus formats' deck has *Part, *Assembly, *Instance
                        as Abaqus/CAE writes it; the others' a flat deck (CalculiX reads it)
  -q, --quiet           no progress lines
  -h, --help            this text

on MPI: mpirun -np N femb-reduce PART.yaml [-o OUT.h5] reduces with reduction.solver: petsc (MUMPS'
  distributed Cholesky and SLEPc's Krylov-Schur over the N ranks; --set reduction.solver=petsc
  for one rank); rank 0 meshes the part (or reads its mesh) and METIS cuts it in N parts, each
  rank assembles its part's columns of K and M, rank 0 prints and writes the file

exit codes: 0 success, 2 bad input (one line names the file, line and key), 3 numerical failure,
  4 refused: the Cholesky factor would not fit in memory (the line says how much it needs).
)";

// --matrix-format's word: a format femb-reduce writes, or an InputError.
femb::MatrixFormat WrittenMatrixFormat(const std::string& word) {
  const std::optional<femb::MatrixFormat> format = femb::KindOf<femb::MatrixFormat>(word);
  if (!format) {
    throw femb::InputError("--matrix-format: unknown format '" + word +
                           "' (known: calculix, abaqus, abaqus_coordinate, matrix_market)");
  }
  if (*format == femb::MatrixFormat::kNastran || *format == femb::MatrixFormat::kAnsys) {
    throw femb::InputError("--matrix-format: " + word +
                           " is read, not written (write calculix, abaqus, abaqus_coordinate or matrix_market)");
  }
  return *format;
}

}  // namespace

int main(int argc, char** argv) {
  RestoreLargeBlockMappings();
  std::string output;
  std::vector<std::string> overrides;
  bool quiet = false;
  std::string export_dir, matrix_format_word = "calculix";
  femb::CommandLine cli("femb-reduce", kUsage, "part file");
  cli.Value({"-o", "--output"}, [&](const std::string& v) { output = v; });
  cli.Value({"--full-modes"}, [&](const std::string& v) { overrides.push_back("reduction.full_modes=" + v); });
  cli.Value({"--set"}, [&](const std::string& v) { overrides.push_back(v); });
  cli.Value({"--export-matrices"}, [&](const std::string& v) { export_dir = v; });
  cli.Value({"--matrix-format"}, [&](const std::string& v) { matrix_format_word = v; });
  cli.Switch({"-q", "--quiet"}, [&] { quiet = true; });
  if (!cli.Parse(argc, argv)) return cli.exit_code();
  const std::string part_path = cli.input();
  // Under an MPI launcher the ranks meet the same input and the same errors: rank 0 says them.
  const bool speaks = femb::LaunchedRank() == 0;
  bool distributed = false;  // on several MPI ranks
#ifdef FEMB_WITH_PETSC
  std::optional<femb::MpiRanks> mpi;  // (outlives everything that uses PETSc)
#endif
  // An error's line and exit code. On MPI ranks before the distributed work, the ranks first agree
  // (femb::AgreeOnStart): the lowest rank that failed says it, and the others, which may be
  // waiting in the solver, stop with its code.
  const auto fail = [&](int code, const std::string& line) {
    bool say = speaks;
    if (distributed && !femb::StartAgreed()) say = femb::AgreeOnStart(code).first_failed == femb::DistributedRank();
    if (say) std::fprintf(stderr, "femb-reduce: %s\n", line.c_str());
    return code;
  };
  try {
    femb::Stopwatch total;
    const femb::MatrixFormat matrix_format = WrittenMatrixFormat(matrix_format_word);
#ifdef FEMB_WITH_PETSC
    // Started by mpirun: MPI first, so that the ranks agree on a failure from the start.
    if (femb::LaunchedRanks() > 0) mpi.emplace();
    distributed = mpi && mpi->size() > 1;
#endif
    const femb::PartSpec part = femb::ReadPartFile(part_path, overrides);
    if (output.empty()) output = part.name + ".h5";
#ifdef FEMB_WITH_PETSC
    if (!mpi && part.reduction.solver == femb::ReductionSolver::kPetsc) mpi.emplace();
#endif
    if (!speaks) quiet = true;
    const bool petsc = femb::ResolvedSolver(part.reduction.solver) == femb::ReductionSolver::kPetsc;
    if (distributed && (!export_dir.empty() || !petsc)) {
      // Only the petsc solver shares the work; anything else rank 0 does alone, once every rank got
      // here.
      const femb::RankAgreement start = femb::AgreeOnStart(0);
      if (start.code != 0) return start.code;
      if (!speaks) return 0;
    }
    // Ranks that share the work also share their memory figures once they agreed to start
    // (AgreeOnStart must be their first collective; after it every rank reports the same stages,
    // so the collective in PeakMemory pairs up).
    const bool shared = distributed && petsc;
    const auto memory = [&]() -> std::string {
#ifdef FEMB_WITH_PETSC
      if (shared) {
        const auto [largest, all] = mpi->PeakMemory();
        char buffer[96];
        std::snprintf(buffer, sizeof buffer, "%.3g GB on the largest rank, %.3g GB in all", largest / 1e9, all / 1e9);
        return buffer;
      }
#endif
      char buffer[32];
      std::snprintf(buffer, sizeof buffer, "%.3g GB", femb::PeakResidentBytes() / 1e9);
      return buffer;
    };
    auto progress = [&](const std::string& stage, double seconds, const std::string& detail) {
      const std::string peak = shared && femb::StartAgreed() ? "; peak memory " + memory() : "";
      if (quiet) return;
      std::printf("femb-reduce: [%8.3f s] %-16s %8.3f s  %s%s\n", total.Seconds(), stage.c_str(), seconds,
                  detail.c_str(), peak.c_str());
      std::fflush(stdout);
    };
    if (!export_dir.empty()) {
      const std::vector<std::string> written = femb::ExportPartMatrices(part, matrix_format, export_dir, progress);
      if (!quiet) std::printf("femb-reduce: wrote %zu files to %s\n", written.size(), export_dir.c_str());
      return 0;
    }
    const femb::ReduceFileOutcome result = femb::ReduceToFile(
        part, output, progress,
        [&](const std::string& line) {
          if (speaks) std::printf("femb-reduce: %s\n", line.c_str());
        },
        speaks);
    if (result.exit_code != 0) return fail(result.exit_code, result.error);
    const std::string peak = memory();
    if (!quiet) {
      std::printf("femb-reduce: wrote %s (%d reduced DOFs from %ld) in %.3f s, peak memory %s\n", output.c_str(),
                  result.superelement.n_reduced_dofs(), result.superelement.n_full_dofs, total.Seconds(), peak.c_str());
    }
    return 0;
  } catch (const femb::RankFailure& e) {
    if (e.said_here()) std::fprintf(stderr, "femb-reduce: %s: %s (no output written)\n", part_path.c_str(), e.what());
    return e.code();
  } catch (const femb::ResourceLimitError& e) {
    return fail(4, part_path + ": refused: " + e.what() + " (no output written)");
  } catch (const femb::InputError& e) {
    return fail(2, e.what());
  } catch (const std::exception& e) {
    // After the ranks' start, a failure inside the distributed solver may be one rank's: that
    // rank says it and ends them all.
#ifdef FEMB_WITH_PETSC
    if (distributed && femb::StartAgreed()) {
      std::fprintf(stderr, "femb-reduce: %s: %s (no output written)\n", part_path.c_str(), e.what());
      mpi->Abort(3);
    }
#endif
    return fail(1, std::string("internal error: ") + e.what());
  }
}
