// The femb-reduce pipeline: part spec -> FE model -> Craig-Bampton -> superelement.
#pragma once

#include <string>
#include <vector>

#include "formats/part_file.h"
#include "formats/superelement.h"
#include "reducer/progress.h"

namespace femb {

struct ReduceResult {
  bool ok = false;
  std::string message;                ///< numerical failure, when !ok
  bool too_big = false;               ///< refused: the factor would not fit in memory (message says how much)
  std::vector<std::string> warnings;  ///< said by femb-reduce, also with -q
  Superelement superelement;
};

/// Input errors throw InputError; numerical failures return ok = false with a message.
ReduceResult ReducePart(const PartSpec& part, const ProgressFn& progress);

}  // namespace femb
