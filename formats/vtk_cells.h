// Cell types and node orders of VTK/XDMF for femb's cells (stored in gmsh node order).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace femb {

/// VTK cell type id: line2 3, tet4 10, hex8 12, tet10 24, hex20 25; the surface cells of
/// imported models tri3 5, quad4 9, tri6 22, quad8 23 (gmsh and VTK orders agree for them).
/// Throws InputError otherwise.
int VtkCellType(const std::string& cell_type);

/// XDMF topology name: Polyline, Tetrahedron, Hexahedron, Tetrahedron_10, Hexahedron_20,
/// Triangle, Quadrilateral, Triangle_6, Quadrilateral_8.
std::string XdmfTopology(const std::string& cell_type);

/// XDMF Mixed-topology cell code: line2 2 (polyline, followed by its node count), tet4 6,
/// hex8 9, tet10 38, hex20 48, tri3 4, quad4 5, tri6 36, quad8 37.
int XdmfMixedCode(const std::string& cell_type);

/// cells (gmsh order) -> cells in VTK/XDMF node order (they differ for tet10 and hex20).
Eigen::MatrixXi ToVtkOrder(const std::string& cell_type, const Eigen::MatrixXi& cells);

}  // namespace femb
