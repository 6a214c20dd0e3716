// The shape functions of femb's solid cells (gmsh node order: TET4, TET10, HEX8, HEX20) and the
// location of a point in a mesh of them: shared by the reducer's elements and the solver's point
// probes, which interpolate a superelement file's mode shapes at any point of the body.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "formats/vtk_cells.h"

namespace femb {

enum class SolidType { kTet4, kTet10, kHex8, kHex20 };

int SolidNodeCount(SolidType type);
/// The mesh cell of a solid element.
CellType CellOf(SolidType type);
/// Its word: "tet4", ...
inline std::string SolidTypeName(SolidType type) { return Name(CellOf(type)); }
/// The solid element of a mesh cell (tet4, tet10, hex8, hex20); nullopt for other cells.
std::optional<SolidType> SolidTypeOf(CellType cell_type);

/// Shape functions (n) and their derivatives (n x 3) at a reference point.
void SolidShapeFunctions(SolidType type, const Eigen::Vector3d& xi, Eigen::VectorXd* N, Eigen::MatrixXd* dN);

/// The reference coordinates of `x` in cell `cell` (rows of `cells` index `nodes`) by Newton on
/// the isoparametric map; true when they lie in the reference cell (within 1e-9).
bool LocateInCell(SolidType type, const Eigen::MatrixXd& nodes, const Eigen::MatrixXi& cells, int cell,
                  const Eigen::Vector3d& x, Eigen::Vector3d* xi);

/// Where a point lies in a mesh: the cell that holds it and the shape function weights of its
/// nodes (solid cells), or else its nearest node (weight 1; any mesh, e.g. beams' lines and
/// imported shells). `distance`: from the point to the nearest node when no cell holds it (0
/// inside); `size`: the longest edge of the cells at the nearest node (the local mesh size).
struct MeshPoint {
  int cell = -1;
  std::vector<int> nodes;
  std::vector<double> weights;
  int nearest = -1;
  double distance = 0.0;
  double size = 0.0;
};
MeshPoint LocateInMesh(const Eigen::MatrixXd& nodes, const Eigen::MatrixXi& cells, CellType cell_type,
                       const Eigen::Vector3d& x);

}  // namespace femb
