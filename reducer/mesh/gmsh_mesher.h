// Meshing with the gmsh C++ API: built-in shapes or a geometry/mesh file (.step, .stp, .brep,
// .geo, .msh), volume elements of order 1 or 2, and named node sets (gmsh physical surface
// groups). Built-in shapes and their face sets:
//   box, plate (a box, usually thin): corner at the origin; xmin, xmax, ymin, ymax, zmin, zmax
//   cylinder: axis z from the origin; bottom (z = 0), top (z = length), outer
//   tube: the same with a bore; bottom, top, outer, inner
#pragma once

#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

#include "formats/kinds.h"
#include "reducer/fe/solid_element.h"

namespace femb {

struct SolidMesh {
  Eigen::MatrixXd nodes;  ///< n x 3
  SolidType type = SolidType::kTet10;
  Eigen::MatrixXi cells;  ///< n_cells x nodes per cell, 0-based, gmsh node order
  std::map<std::string, std::vector<int>> node_sets;
};

struct MeshRequest {
  SolidShape shape = SolidShape::kFile;  ///< a built-in shape, or kFile: `file`
  Eigen::Vector3d size = Eigen::Vector3d::Ones();
  double radius = 0.0, inner_radius = 0.0, length = 0.0;  ///< cylinder / tube along z
  std::string file;                                       ///< geometry or mesh file
  double element_size = 0.0;                              ///< target element size [length]
  int order = 2;
  bool hexahedra = false;       ///< structured hexahedra (built-in box only): HEX8 / HEX20
  long max_elements = 3000000;  ///< refuse to mesh when the estimated element count exceeds it
  std::string where;            ///< location for messages
};

/// Throws InputError (naming `where` or the file) for an unreadable file, no volume elements,
/// or unsupported element types; ResourceLimitError, before meshing, when the element count
/// estimated from the geometry's volume V and the size h (about 6 V / h^3 tetrahedra, measured
/// 5-6 on gmsh meshes of the examples; V / h^3 hexahedra) exceeds max_elements.
SolidMesh MeshWithGmsh(const MeshRequest& request);

}  // namespace femb
