// Mode shapes as VTK unstructured grids (.vtu, ASCII XML) that ParaView opens: one file per
// reduced coordinate (its label, as in femb-inspect's list, in an XML comment), the mesh with
// point data 'displacement' (and 'rotation' for beams).
#pragma once

#include <string>

#include "formats/superelement.h"

namespace femb {

/// Writes DIR/<name>_<i>.vtu for each reduced coordinate i (atomic per file) and returns how
/// many. Throws InputError when the file holds no mesh (reduction.keep_mesh: false) or DIR
/// cannot be written.
int WriteModeShapesVtu(const Superelement& se, const std::string& directory);

}  // namespace femb
