// Cell codes and node orders for VTK and XDMF (formats/vtk_cells.h) against VTK's own
// definitions: VTK_QUADRATIC_TETRA puts its edge nodes on the edges (01, 12, 20, 03, 13, 23),
// VTK_QUADRATIC_HEXAHEDRON on (01, 12, 23, 30, 45, 56, 67, 74, 04, 15, 26, 37), and the linear
// cells' corners agree with gmsh's. Where gmsh puts each node is read from femb's shape
// functions (formats/solid_shape.h: N_i is 1 at node i and 0 at the others).
#include "formats/vtk_cells.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <set>
#include <utility>
#include <vector>

#include "formats/solid_shape.h"

namespace femb {
namespace {

using Edge = std::pair<int, int>;

// Reference coordinates of every node of a solid cell in gmsh order: among the corners and the
// midpoints of every pair of corners, the point where the node's shape function is 1.
std::vector<Eigen::Vector3d> NodePositions(SolidType type) {
  const bool tet = type == SolidType::kTet4 || type == SolidType::kTet10;
  std::vector<Eigen::Vector3d> corners;
  if (tet) {
    corners = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, 0, 1)};
  } else {
    for (int z : {-1, 1}) {
      corners.insert(corners.end(), {Eigen::Vector3d(-1, -1, z), Eigen::Vector3d(1, -1, z), Eigen::Vector3d(1, 1, z),
                                     Eigen::Vector3d(-1, 1, z)});
    }
  }
  std::vector<Eigen::Vector3d> candidates = corners;
  for (size_t a = 0; a < corners.size(); ++a)
    for (size_t b = a + 1; b < corners.size(); ++b) candidates.push_back((corners[a] + corners[b]) / 2);
  const int n = SolidNodeCount(type);
  std::vector<Eigen::Vector3d> at(size_t(n), Eigen::Vector3d::Constant(99));
  Eigen::VectorXd N;
  Eigen::MatrixXd dN;
  for (const Eigen::Vector3d& x : candidates) {
    SolidShapeFunctions(type, x, &N, &dN);
    for (int i = 0; i < n; ++i) {
      if (std::abs(N[i] - 1) < 1e-12) at[size_t(i)] = x;
    }
  }
  for (int i = 0; i < n; ++i) EXPECT_LT(at[size_t(i)].norm(), 10) << "node " << i << " not found";
  return at;
}

// VTK's node order of a cell given in gmsh order: node p of VTK's cell is corner p (p below the
// corner count) or the midpoint of VTK's edge p - corners.
void ExpectVtkOrder(SolidType type, int corners, const std::vector<Edge>& vtk_edges) {
  const int n = SolidNodeCount(type);
  const std::vector<Eigen::Vector3d> x = NodePositions(type);
  Eigen::MatrixXi cell(1, n);
  for (int i = 0; i < n; ++i) cell(0, i) = i;
  const Eigen::MatrixXi vtk = ToVtkOrder(CellOf(type), cell);
  ASSERT_EQ(vtk.cols(), n);
  std::set<int> used;
  for (int p = 0; p < n; ++p) used.insert(vtk(0, p));
  EXPECT_EQ(int(used.size()), n) << "not a permutation";
  for (int p = 0; p < corners; ++p) EXPECT_EQ(vtk(0, p), p) << SolidTypeName(type) << " corner " << p;
  for (int p = corners; p < n; ++p) {
    const auto [a, b] = vtk_edges[size_t(p - corners)];
    const Eigen::Vector3d mid = (x[size_t(vtk(0, a))] + x[size_t(vtk(0, b))]) / 2;
    EXPECT_LT((x[size_t(vtk(0, p))] - mid).norm(), 1e-14) << SolidTypeName(type) << " VTK node " << p;
  }
}

TEST(VtkCells, QuadraticTetraAndHexahedronNodesLieOnVtksEdges) {
  ExpectVtkOrder(SolidType::kTet4, 4, {});
  ExpectVtkOrder(SolidType::kHex8, 8, {});
  ExpectVtkOrder(SolidType::kTet10, 4, {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}});
  ExpectVtkOrder(SolidType::kHex20, 8,
                 {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6}, {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}});
}

TEST(VtkCells, EveryCellHasVtksAndXdmfsCodes) {
  // VTK's vtkCellType.h and XDMF's topology names and Mixed codes.
  const struct {
    CellType type;
    int vtk;
    const char* xdmf;
    int mixed;
  } expected[] = {{CellType::kLine2, 3, "Polyline", 2},          {CellType::kTri3, 5, "Triangle", 4},
                  {CellType::kTri6, 22, "Triangle_6", 36},       {CellType::kQuad4, 9, "Quadrilateral", 5},
                  {CellType::kQuad8, 23, "Quadrilateral_8", 37}, {CellType::kTet4, 10, "Tetrahedron", 6},
                  {CellType::kTet10, 24, "Tetrahedron_10", 38},  {CellType::kHex8, 12, "Hexahedron", 9},
                  {CellType::kHex20, 25, "Hexahedron_20", 48}};
  EXPECT_EQ(std::size(expected), std::size(Words<CellType>::list));
  for (const auto& e : expected) {
    EXPECT_EQ(VtkCellType(e.type), e.vtk) << Name(e.type);
    EXPECT_STREQ(XdmfTopology(e.type), e.xdmf) << Name(e.type);
    EXPECT_EQ(XdmfMixedCode(e.type), e.mixed) << Name(e.type);
  }
  // The surface cells keep gmsh's order, which is VTK's for them.
  const Eigen::MatrixXi quad8 = (Eigen::MatrixXi(1, 8) << 7, 6, 5, 4, 3, 2, 1, 0).finished();
  EXPECT_EQ(ToVtkOrder(CellType::kQuad8, quad8), quad8);
}

TEST(VtkCells, SolidElementsAndCellsCorrespond) {
  for (SolidType t : {SolidType::kTet4, SolidType::kTet10, SolidType::kHex8, SolidType::kHex20}) {
    EXPECT_EQ(SolidTypeOf(CellOf(t)), t);
    EXPECT_EQ(CellNodeCount(CellOf(t)), SolidNodeCount(t));
    EXPECT_EQ(SolidTypeName(t), Name(CellOf(t)));
  }
  const std::pair<CellType, int> surface[] = {
      {CellType::kLine2, 2}, {CellType::kTri3, 3}, {CellType::kTri6, 6}, {CellType::kQuad4, 4}, {CellType::kQuad8, 8}};
  for (const auto& [c, nodes] : surface) {
    EXPECT_FALSE(SolidTypeOf(c).has_value()) << Name(c);
    EXPECT_EQ(CellNodeCount(c), nodes) << Name(c);
  }
}

}  // namespace
}  // namespace femb
