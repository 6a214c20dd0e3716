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

#include "formats/part_file.h"
#include "reducer/fe/fe_model.h"
#include "reducer/mesh/gmsh_mesher.h"
#include "reducer/progress.h"

namespace femb {

/// Throws InputError for a missing or empty node set, node sets that overlap, or an inverted
/// element (named).
/// Reports the stages mesh, assembly and couplings through `progress` (may be null).
FeModel BuildSolidModel(const PartSpec& part, const ProgressFn& progress = nullptr);

/// Symmetric K and M of the mesh DOFs (3 per node) assembled into a sparsity pattern computed
/// once from the node graph: K with full 3 x 3 node blocks, M with their diagonals only
/// (consistent mass couples like components). No triplet lists: memory is the matrices.
void AssembleSolid(const SolidMesh& mesh, const MaterialSpec& material, SparseMatrix* K, SparseMatrix* M);

}  // namespace femb
