// Reading and writing superelement files (HDF5). Schema: formats/SUPERELEMENT_FORMAT.md.
#pragma once

#include <string>

#include "formats/superelement.h"

namespace femb {

inline constexpr long kSuperelementFormatMajor = 1;
inline constexpr long kSuperelementFormatMinor = 0;
inline constexpr const char* kSuperelementFormatTag = "femb-superelement";

/// Writes `se` to `path` atomically: to `path.tmp.<pid>` first, then renamed over `path`, so a
/// crash never leaves a half-written file. Throws InputError (file named) on failure.
void WriteSuperelementFile(const Superelement& se, const std::string& path);

/// What to read besides the always-present data.
struct SuperelementReadOptions {
  bool visualization = true;  ///< read the (possibly large) mesh and mode shapes if present
  bool stress = true;         ///< with the mesh: read the modal stresses if present
};

/// Reads a superelement file. Throws InputError naming the file and the problem for: a missing
/// or non-HDF5 or truncated file, another major format version, a missing dataset, or datasets
/// whose shapes disagree.
Superelement ReadSuperelementFile(const std::string& path, const SuperelementReadOptions& options = {});

}  // namespace femb
