// A linear finite element model of one part, ready for reduction: sparse K and M over all DOFs,
// the mesh (for visualization) and the interface nodes.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "formats/vtk_cells.h"

namespace femb {

using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

/// A full-model DOF number, distinct from interface and reduced coordinate numbers.
struct FullDof {
  int value;
};

/// A contiguous range of a matrix's columns: those one MPI rank holds of a matrix shared by
/// columns (reducer/linalg/shared_columns.h). count < 0: every column (one process).
struct ColumnShare {
  long first = 0;
  long count = -1;
  bool whole() const { return count < 0; }
  long end(long n) const { return whole() ? n : first + count; }
  bool Holds(long column) const { return whole() || (column >= first && column < first + count); }
};

struct FeModel {
  int dofs_per_node = 6;  ///< 6 for beams (u, theta); 3 for solids
  Eigen::MatrixXd nodes;  ///< n_nodes x 3, part axes
  Eigen::MatrixXi cells;  ///< n_cells x nodes_per_cell
  CellType cell_type = CellType::kLine2;
  std::string element_type;  ///< e.g. "timoshenko_beam"
  SparseMatrix K, M;         ///< n_dofs x n_dofs, full (both triangles stored)
  /// The columns of K and M this process holds: all of them, or on the MPI ranks of a distributed
  /// reduction its share (the other columns are empty; shared_columns.h).
  ColumnShare columns;
  /// A solid on MPI ranks cut by METIS: the cells of this rank's part, ascending, which it takes in
  /// the loops over the elements after the reduction (RankMeshOf). Empty otherwise.
  std::vector<int> rank_cells;

  /// Boundary coordinates: 6 per interface, ordered (u_x, u_y, u_z, th_x, th_y, th_z) in part
  /// axes. For beams these are DOFs of interface nodes directly.
  std::vector<std::string> interface_names;
  std::vector<Eigen::Vector3d> interface_positions;
  std::vector<std::vector<FullDof>> interface_dofs;  ///< 6 full DOFs per interface (empty: see below)
  /// Interfaces tied by a distributing (RBE3) coupling are not DOFs of the model: their six
  /// coordinates are q_k = W_k u, a weighted rigid fit of the node set. interface_weights[k] is
  /// W_k (6 x n_dofs) for those and has no rows for DOF interfaces (or is absent for beams).
  std::vector<SparseMatrix> interface_weights;
  /// Per interface: the mesh nodes its coupling ties (RBE2 and RBE3 sets; a beam's interface is
  /// its own node), in the numbering of `nodes`.
  std::vector<std::vector<int>> interface_node_sets;

  /// (u, theta) of the material point at `x` as a 6 x n_dofs matrix acting on full DOF vectors;
  /// nullopt when `x` lies outside the material.
  std::function<std::optional<SparseMatrix>(const Eigen::Vector3d& x)> interpolate_at;

  /// Solids: mesh DOFs (3 per mesh node) = mesh_map * model DOFs (the RBE2 couplings eliminate
  /// the coupled nodes in favour of the 6-DOF interface nodes). Empty for beams (identity).
  SparseMatrix mesh_map;

  /// Imported models (several DOF layouts per node: solids 3, shells and beams 6): the point
  /// (part axes) and component (0..5: u_x, u_y, u_z, theta_x, theta_y, theta_z) of every model
  /// DOF, for the rigid-body fields. Empty for femb's own models.
  std::vector<Eigen::Vector3d> dof_point;
  std::vector<int> dof_component;
  /// Imported models: the node each model DOF belongs to (the imported node's index, or
  /// n_nodes + k for the six DOFs of RBE2 interface k): the DOFs of one node and kind
  /// (translation, rotation) are the components of one vector.
  std::vector<int> dof_node;
  /// Imported models: the imported DOFs (the matrices' rows) = full_map * model DOFs.
  SparseMatrix full_map;

  long n_dofs() const { return long(K.rows()); }
  long n_nodes() const { return long(nodes.rows()); }
  long n_elements() const { return long(cells.rows()); }
};

}  // namespace femb
