#include "formats/vtk_cells.h"

#include <vector>

namespace femb {

namespace {

struct CellCodes {
  CellType type;
  int vtk;
  const char* xdmf;
  int mixed;
  int nodes;
};

constexpr CellCodes kCellCodes[] = {
    {CellType::kLine2, 3, "Polyline", 2, 2},         {CellType::kTet4, 10, "Tetrahedron", 6, 4},
    {CellType::kHex8, 12, "Hexahedron", 9, 8},       {CellType::kTet10, 24, "Tetrahedron_10", 38, 10},
    {CellType::kHex20, 25, "Hexahedron_20", 48, 20}, {CellType::kTri3, 5, "Triangle", 4, 3},
    {CellType::kQuad4, 9, "Quadrilateral", 5, 4},    {CellType::kTri6, 22, "Triangle_6", 36, 6},
    {CellType::kQuad8, 23, "Quadrilateral_8", 37, 8}};

const CellCodes& CodesOf(CellType type) {
  for (const CellCodes& c : kCellCodes) {
    if (c.type == type) return c;
  }
  return kCellCodes[0];  // every CellType has its row above
}

}  // namespace

int VtkCellType(CellType type) { return CodesOf(type).vtk; }

const char* XdmfTopology(CellType type) { return CodesOf(type).xdmf; }

int XdmfMixedCode(CellType type) { return CodesOf(type).mixed; }

int CellNodeCount(CellType type) { return CodesOf(type).nodes; }

Eigen::MatrixXi ToVtkOrder(CellType type, const Eigen::MatrixXi& cells) {
  std::vector<int> order;
  // gmsh tet10 edges (01, 12, 02, 03, 23, 13); VTK (01, 12, 02, 03, 13, 23).
  if (type == CellType::kTet10) order = {0, 1, 2, 3, 4, 5, 6, 7, 9, 8};
  // gmsh hex20 edges (01, 03, 04, 12, 15, 23, 26, 37, 45, 47, 56, 67);
  // VTK (01, 12, 23, 30, 45, 56, 67, 74, 04, 15, 26, 37).
  if (type == CellType::kHex20) order = {0, 1, 2, 3, 4, 5, 6, 7, 8, 11, 13, 9, 16, 18, 19, 17, 10, 12, 14, 15};
  if (order.empty()) return cells;
  Eigen::MatrixXi out(cells.rows(), cells.cols());
  for (int c = 0; c < int(order.size()); ++c) out.col(c) = cells.col(order[c]);
  return out;
}

}  // namespace femb
