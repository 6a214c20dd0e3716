// Beam parts: a polyline of points and segments meshed into 2-node Timoshenko elements.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "formats/part_file.h"
#include "reducer/fe/fe_model.h"
#include "reducer/fe/timoshenko_beam.h"

namespace femb {

/// Meshes and assembles a beam part. Each segment gets `elements` equal elements; points shared
/// by segments are shared nodes. Orientation: the part's vector, else global Y, else (for
/// segments along Y) global Z. Throws InputError naming the segment when the orientation vector
/// is parallel to it.
FeModel BuildBeamModel(const PartSpec& part);

/// The elements of that mesh (nodes n1, n2; local axes R, rows e1 e2 e3; the element) and, in
/// `nodes`, the node positions (the part's points first, then the segments' inner nodes).
struct BeamElement {
  int n1, n2;
  Eigen::Matrix3d R;
  std::shared_ptr<const TimoshenkoBeam> beam;
};
std::vector<BeamElement> BeamElements(const PartSpec& part, std::vector<Eigen::Vector3d>* nodes);

}  // namespace femb
