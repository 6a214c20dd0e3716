// femb-reduce's job from a part spec to a superelement file, as the program and the Python
// module's femb.reduce both do it: the reduction (ReducePart), the file's contract checked
// (formats/superelement_checks.h: a model that fails it is not written), then the file written
// under a temporary name and renamed.
#pragma once

#include <functional>
#include <string>

#include "formats/part_file.h"
#include "formats/superelement.h"
#include "reducer/progress.h"

namespace femb {

struct ReduceFileOutcome {
  /// femb-reduce's exit code: 0 written, 3 numerical failure, 4 refused (the Cholesky factor
  /// would not fit in memory).
  int exit_code = 0;
  std::string error;          ///< when not written: the line femb-reduce writes to stderr (after its name)
  Superelement superelement;  ///< the model written
};

/// Reduces `part` and writes it to `output`. Progress to `progress` (stages with their times,
/// then "checks", "dynamics" and "write"); warnings to `warning`. Bad input throws InputError;
/// nothing is written unless the outcome's exit code is 0.
/// With `write` false (the ranks other than 0 of a distributed run), everything but the file.
ReduceFileOutcome ReduceToFile(const PartSpec& part, const std::string& output, const ProgressFn& progress,
                               const std::function<void(const std::string&)>& warning, bool write = true);

}  // namespace femb
