// Foreign mesh formats (Abaqus .inp, Nastran .bdf, VTK/VTU, MED, ...) through meshio: the
// Python bridge formats/meshio_bridge.py (run with Debian's /usr/bin/python3) writes femb's
// plain-text mesh, read here. Named node sets: meshio's point sets and the nodes of its named
// cell sets.
#pragma once

#include <string>

#include "reducer/mesh/gmsh_mesher.h"

namespace femb {

/// true for extensions gmsh reads itself (.msh, .geo, .step, .stp, .brep).
bool IsGmshFile(const std::string& path);

/// A mesh as the bridge reads it: any cell type femb draws, and the file's node labels.
struct ForeignMesh {
  Eigen::MatrixXd nodes;                 ///< n x 3
  std::vector<long> ids;                 ///< node labels of the file (.inp, .bdf), else 1..n in file order
  CellType cell_type = CellType::kTet4;  ///< solids; with any_cells also tri3, tri6, quad4, quad8, line2
  Eigen::MatrixXi cells;                 ///< 0-based, gmsh node order
  std::map<std::string, std::vector<int>> node_sets;
};

/// Throws InputError for: python3 or meshio missing (with the apt-get line), an unreadable
/// file, no volume elements (with any_cells: no cells at all).
ForeignMesh ReadWithMeshio(const std::string& path, const std::string& where, bool any_cells);

/// The same for solid parts: volume elements only.
SolidMesh ImportWithMeshio(const std::string& path, const std::string& where);

}  // namespace femb
