#include "formats/vtk_cells.h"

#include "formats/input_error.h"

namespace femb {

int VtkCellType(const std::string& t) {
  if (t == "line2") return 3;
  if (t == "tet4") return 10;
  if (t == "hex8") return 12;
  if (t == "tet10") return 24;
  if (t == "hex20") return 25;
  if (t == "tri3") return 5;
  if (t == "quad4") return 9;
  if (t == "tri6") return 22;
  if (t == "quad8") return 23;
  throw InputError("cell type '" + t + "' has no VTK equivalent");
}

std::string XdmfTopology(const std::string& t) {
  if (t == "line2") return "Polyline";
  if (t == "tet4") return "Tetrahedron";
  if (t == "hex8") return "Hexahedron";
  if (t == "tet10") return "Tetrahedron_10";
  if (t == "hex20") return "Hexahedron_20";
  if (t == "tri3") return "Triangle";
  if (t == "quad4") return "Quadrilateral";
  if (t == "tri6") return "Triangle_6";
  if (t == "quad8") return "Quadrilateral_8";
  throw InputError("cell type '" + t + "' has no XDMF equivalent");
}

int XdmfMixedCode(const std::string& t) {
  if (t == "line2") return 2;
  if (t == "tet4") return 6;
  if (t == "hex8") return 9;
  if (t == "tet10") return 38;
  if (t == "hex20") return 48;
  if (t == "tri3") return 4;
  if (t == "quad4") return 5;
  if (t == "tri6") return 36;
  if (t == "quad8") return 37;
  throw InputError("cell type '" + t + "' has no XDMF equivalent");
}

Eigen::MatrixXi ToVtkOrder(const std::string& t, const Eigen::MatrixXi& cells) {
  std::vector<int> order;
  // gmsh tet10 edges (01, 12, 02, 03, 23, 13); VTK (01, 12, 02, 03, 13, 23).
  if (t == "tet10") order = {0, 1, 2, 3, 4, 5, 6, 7, 9, 8};
  // gmsh hex20 edges (01, 03, 04, 12, 15, 23, 26, 37, 45, 47, 56, 67);
  // VTK (01, 12, 23, 30, 45, 56, 67, 74, 04, 15, 26, 37).
  if (t == "hex20") order = {0, 1, 2, 3, 4, 5, 6, 7, 8, 11, 13, 9, 16, 18, 19, 17, 10, 12, 14, 15};
  if (order.empty()) return cells;
  Eigen::MatrixXi out(cells.rows(), cells.cols());
  for (int c = 0; c < int(order.size()); ++c) out.col(c) = cells.col(order[c]);
  return out;
}

}  // namespace femb
