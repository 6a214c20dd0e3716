#include "reducer/reduce_file.h"

#include <filesystem>

#include "formats/input_error.h"
#include "formats/superelement_checks.h"
#include "formats/superelement_file.h"
#include "reducer/linalg/interior_solver.h"
#include "reducer/linalg/shared_columns.h"
#include "reducer/linalg/sparse_cholesky.h"
#include "reducer/reduce_part.h"

namespace femb {

ReduceFileOutcome ReduceToFile(const PartSpec& part, const std::string& output, const ProgressFn& progress,
                               const std::function<void(const std::string&)>& warning, bool write) {
  ReduceFileOutcome out;
  const auto refuse = [&](int code, const std::string& what) {
    out.exit_code = code;
    out.error = part.file + ": " + what + " (no output written)";
    return out;
  };
  // The output's folder is made (or found unwritable) before the work, not after it.
  const std::filesystem::path folder = std::filesystem::path(output).parent_path();
  if (!folder.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(folder, ec);
    if (ec) throw InputError(output + ": cannot create the folder " + folder.string() + " (" + ec.message() + ")");
  }
  ReduceResult result;
  try {
    result = ReducePart(part, progress);
  } catch (const ResourceLimitError& e) {
    return refuse(4, std::string("refused: ") + e.what());
  }
  if (!result.ok && result.too_big) return refuse(4, "refused: " + result.message);
  if (!result.ok) return refuse(3, "numerical failure: " + result.message);
  for (const std::string& w : result.warnings)
    if (warning) warning("warning: " + part.file + ": " + w);
  Stopwatch check_clock;
  const SuperelementChecks checks = CheckSuperelement(result.superelement);
  const Check* c = checks.first_failure();
  std::string failure = c ? "the reduced model fails check " + c->name + ": " + c->detail : "";
  // (on the MPI ranks sharing the reduction rank 0's verdict: it alone holds the stresses and the
  // mesh shapes whole)
  if (ResolvedSolver(part.reduction.solver) == ReductionSolver::kPetsc && DistributedRanks() > 1)
    failure = FromFirstRank(failure);
  if (!failure.empty()) {
    return refuse(3, "numerical failure: " + failure +
                         "; the part may be nearly a mechanism (a region held by a connection many orders of "
                         "magnitude softer than the rest) or ill-conditioned");
  }
  if (progress) {
    progress("checks", check_clock.Seconds(), std::to_string(checks.checks.size()) + " checks passed");
    progress("dynamics", 0.0, DynamicsSummary(result.superelement));
  }
  Stopwatch write_clock;
  if (write) WriteSuperelementFile(result.superelement, output);
  if (progress) progress("write", write_clock.Seconds(), output);
  out.superelement = std::move(result.superelement);
  return out;
}

}  // namespace femb
