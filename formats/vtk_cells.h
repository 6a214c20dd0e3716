// The cells of femb's meshes (gmsh node order), their words in files, and their VTK/XDMF types
// and node orders.
#pragma once

#include <Eigen/Core>

#include "formats/kinds.h"

namespace femb {

/// A mesh cell: the solids of femb's own parts, beams' lines, and the surface cells of
/// imported models. The superelement file's /visualization cell_type holds its word.
enum class CellType { kLine2, kTri3, kTri6, kQuad4, kQuad8, kTet4, kTet10, kHex8, kHex20 };
template <>
struct Words<CellType> {
  static constexpr KindWord<CellType> list[] = {
      {CellType::kLine2, "line2"}, {CellType::kTri3, "tri3"},   {CellType::kTri6, "tri6"},
      {CellType::kQuad4, "quad4"}, {CellType::kQuad8, "quad8"}, {CellType::kTet4, "tet4"},
      {CellType::kTet10, "tet10"}, {CellType::kHex8, "hex8"},   {CellType::kHex20, "hex20"}};
};

/// VTK cell type id: line2 3, tet4 10, hex8 12, tet10 24, hex20 25, tri3 5, quad4 9, tri6 22,
/// quad8 23 (gmsh and VTK orders agree for the surface cells).
int VtkCellType(CellType type);

/// XDMF topology name: Polyline, Tetrahedron, Hexahedron, Tetrahedron_10, Hexahedron_20,
/// Triangle, Quadrilateral, Triangle_6, Quadrilateral_8.
const char* XdmfTopology(CellType type);

/// XDMF Mixed-topology cell code: line2 2 (polyline, followed by its node count), tet4 6,
/// hex8 9, tet10 38, hex20 48, tri3 4, quad4 5, tri6 36, quad8 37.
int XdmfMixedCode(CellType type);

/// Nodes of one cell: line2 2, tri3 3, tri6 6, quad4 4, quad8 8, tet4 4, tet10 10, hex8 8, hex20 20.
int CellNodeCount(CellType type);

/// cells (gmsh order) -> cells in VTK/XDMF node order (they differ for tet10 and hex20).
Eigen::MatrixXi ToVtkOrder(CellType type, const Eigen::MatrixXi& cells);

}  // namespace femb
