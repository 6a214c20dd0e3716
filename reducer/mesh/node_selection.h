// Interface node sets picked by geometry (part key interfaces[k].select): the mesh
// nodes whose distance to a surface is at most the tolerance,
//   cylinder  | |(x - p) x a| - r | <= tol  (and -tol <= (x - p).a <= length + tol when bounded)
//   sphere    | |x - c| - r | <= tol
//   plane     | (x - p).n | <= tol
// or inside a box grown by the tolerance. Works on any mesh: gmsh, meshio imports, and the node
// coordinates of imported matrices.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "formats/part_file.h"

namespace femb {

/// Distance of x from the selection's surface (box: from the box, 0 inside).
double SelectionDistance(const NodeSelectionSpec& s, const Eigen::Vector3d& x);

/// The nodes (rows of `nodes`) within the tolerance, ascending. The tolerance defaults to 1e-4 x
/// the bounding-box diagonal of `nodes`. Throws InputError naming `s.where` and the interface
/// when no node is selected (with the nearest node's distance, so a unit or tolerance slip shows).
std::vector<int> SelectNodes(const NodeSelectionSpec& s, const Eigen::MatrixXd& nodes, const std::string& interface);

/// "cylinder r = 0.01 through (0, 0, 0) along (0, 0, 1)" and the like, for progress lines.
std::string DescribeSelection(const NodeSelectionSpec& s);

}  // namespace femb
