// Beam parts: a polyline of points and segments meshed into 2-node Timoshenko elements.
#pragma once

#include "formats/part_file.h"
#include "reducer/fe/fe_model.h"

namespace femb {

/// Meshes and assembles a beam part. Each segment gets `elements` equal elements; points shared
/// by segments are shared nodes. Orientation: the part's vector, else global Y, else (for
/// segments along Y) global Z. Throws InputError naming the segment when the orientation vector
/// is parallel to it.
FeModel BuildBeamModel(const PartSpec& part);

}  // namespace femb
