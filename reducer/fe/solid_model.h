// Solid parts: gmsh mesh -> solid elements -> K, M on the mesh DOFs -> interface couplings.
// RBE2 (rigid): every node of the interface's node set moves with the 6-DOF interface node,
//   u_s = u_k + theta_k x (x_s - x_k), i.e. mesh DOFs = T * model DOFs with T built from
//   [1, -(x_s - x_k)~] blocks; K = T^T K_mesh T, M = T^T M_mesh T. It stiffens the coupled face
//   (use it for a bolted flange or a shaft seat that is truly rigid).
// RBE3 (distributing): the interface's six coordinates are the least-squares rigid fit of its
//   node set, q_k = W_k u; the set stays free (no stiffness added: a bearing seat, a load
//   introduction that must not stiffen the part). The reduction imposes q = W u as a constraint
//   (FeModel::interface_weights).
// The interface point defaults to the centroid of the node set.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <optional>

#include "formats/part_file.h"
#include "reducer/fe/fe_model.h"
#include "reducer/mesh/gmsh_mesher.h"
#include "reducer/progress.h"

namespace femb {

/// The part's mesh: gmsh (built-in shapes, geometry and .msh files) or meshio (other mesh files),
/// its size checked against the unit system.
SolidMesh MeshSolidPart(const PartSpec& part);

/// Throws InputError for a missing or empty node set, node sets that overlap, or an inverted
/// element (named).
/// Reports the stages mesh, assembly and couplings through `progress` (may be null). The whole K
/// and M (on MPI ranks: BuildSolidModelOnRanks, solid_ranks.h).
FeModel BuildSolidModel(const PartSpec& part, const ProgressFn& progress = nullptr);

/// The MPI ranks' partition of a solid mesh (solid_ranks.h): the part of every mesh node, 0 to
/// parts - 1, one part per rank, and of every cell (the element loops' share of the rank).
struct NodePartition {
  std::vector<int> part;
  std::vector<int> cell_part;
  int parts = 1;
};

/// BuildSolidModel on a mesh made already, without its "mesh" stage. `shared`: K and M only in
/// this MPI rank's share of the columns (FeModel::columns), from the elements that touch them:
/// with a `partition` the model's DOFs are numbered part by part, the RBE2 interfaces' last, and
/// this rank holds its part's columns (it assembles the elements of its part and those touching
/// it only); without, the DOFs as meshed and an even share (ShareOfColumns).
FeModel BuildSolidModelOn(const PartSpec& part, const std::shared_ptr<const SolidMesh>& mesh, bool shared,
                          const NodePartition* partition, const ProgressFn& progress);

/// The "mesh" stage's progress text: nodes, elements and the mesh file.
std::string MeshSummary(const PartSpec& part, const SolidMesh& mesh);

/// How mesh node s enters the model: its displacement is T_s q_P, P = model_node[s], whose
/// model DOFs are first_dof[P] .. first_dof[P] + dofs[P] - 1: 3 for a free node (T_s = 1), 6 for
/// an RBE2 interface node (T_s = [1, arm[s]], arm = -(x_s - x_k)~). Model nodes are numbered in
/// the order of their first DOF.
struct SolidDofMap {
  std::vector<int> model_node;       ///< per mesh node
  std::vector<int> first_dof, dofs;  ///< per model node
  std::vector<Eigen::Matrix3d> arm;  ///< per mesh node (RBE2 nodes only)
  int n_dofs = 0;
};

/// Symmetric K and M on the model DOFs, RBE2 couplings folded in element by element
/// (T_e^T K_e T_e), assembled into a sparsity pattern computed once from the model-node graph:
/// K with full node blocks, M with the diagonals only between free nodes (consistent mass
/// couples like components). No triplet lists and no sparse products: memory is the matrices.
/// Only the columns `held` get entries (the others are empty), from the elements that touch them.
/// Returns the number of elements assembled.
long AssembleSolid(const SolidMesh& mesh, const MaterialSpec& material, const SolidDofMap& map, SparseMatrix* K,
                   SparseMatrix* M, const ColumnShare& held = ColumnShare());

/// The area-weighted centroid of the boundary faces whose corners all lie in `set` (the default
/// interface point: on a bore's axis, where the nodes' mean is not); none when the set has no face.
std::optional<Eigen::Vector3d> SurfaceCentroid(const SolidMesh& mesh, const std::vector<int>& set);

/// The RBE3 weights W (6 x 3 |set|, node by node): the interface's (u, theta) at `point` from the
/// least-squares rigid fit of the set's displacements. Throws InputError (naming `where` and the
/// interface) for fewer than 3 nodes or nodes on one line.
Eigen::MatrixXd Rbe3Weights(const Eigen::MatrixXd& nodes, const std::vector<int>& set, const Eigen::Vector3d& point,
                            const std::string& where, const std::string& name);

/// The node sets of a part's interfaces on a mesh: a named set of `node_sets` or the nodes picked
/// by geometry (`select`), kept only where `keep` (null: all) says so, each with its reference
/// point (the interface's `location`, else the surface centroid of the set on `volume` when it
/// has faces there, else the mean of its nodes).
struct InterfaceNodes {
  std::vector<std::vector<int>> sets;      ///< per interface
  std::vector<int> owner;                  ///< per mesh node: its interface, or -1
  std::vector<Eigen::Vector3d> positions;  ///< per interface
  std::string summary;                     ///< "A: 12 nodes by cylinder, B: ..." (progress line)
};
/// Throws InputError naming the interface for a set missing from `node_sets` (listing the known
/// ones; `mesh_name` says where it was looked for), an empty set, a set without a kept node
/// (`keep_reason` says why nodes are dropped) and sets that share nodes.
InterfaceNodes ResolveInterfaceNodes(const PartSpec& part, const Eigen::MatrixXd& nodes,
                                     const std::map<std::string, std::vector<int>>& node_sets, const SolidMesh* volume,
                                     const std::string& mesh_name, const std::function<bool(int)>& keep = nullptr,
                                     const std::string& keep_reason = "");

/// FeModel::interpolate_at for a volume mesh whose mesh DOFs (3 per node) are T x model DOFs:
/// displacement and small rotation (curl / 2) of the element containing x.
std::function<std::optional<SparseMatrix>(const Eigen::Vector3d&)> SolidInterpolation(
    std::shared_ptr<const SolidMesh> mesh, const SparseMatrix& T);

}  // namespace femb
