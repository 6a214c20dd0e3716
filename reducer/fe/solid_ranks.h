// A solid part on the MPI ranks of a distributed reduction: rank 0 alone meshes the part (or reads
// its mesh) and partitions it with METIS, one part per rank (the elements by their dual graph,
// joined where they share a face; each node given to a part of its elements). Every rank receives
// the mesh and the partition, numbers the model's DOFs part by part and holds its own part's
// columns of K and M: it assembles the elements of its part and those touching it, about 1/N of
// them, where an unpartitioned numbering (as meshed) has every rank touch nearly all.
#pragma once

#include <string>

#include "formats/part_file.h"
#include "reducer/fe/fe_model.h"
#include "reducer/fe/solid_model.h"
#include "reducer/progress.h"

namespace femb {

/// The part of every node of `mesh` among `parts` (METIS_PartMeshDual); all 0 for one part.
/// `cells_per_part` (may be null): the elements METIS put in each part.
NodePartition PartitionMesh(const SolidMesh& mesh, int parts, std::vector<long>* cells_per_part = nullptr);

/// The mesh and its partition as bytes (what rank 0 sends the others), and back.
std::string MeshBytes(const SolidMesh& mesh, const NodePartition& partition);
SolidMesh MeshFromBytes(const std::string& bytes, NodePartition* partition);

/// Throws RankFailure (exit 2, said by rank 0) unless every rank was given the same part (its
/// file's text after --set): each builds the model from its own part spec.
void CheckSamePartOnRanks(const PartSpec& part);

/// The cells a rank takes in the loops over the elements after the reduction (stiffening,
/// stresses), on a compact numbering of the nodes they touch: on one process all of them, the
/// mesh as it is; on MPI ranks its METIS part's (FeModel::rank_cells), or an even share of them
/// where the mesh was not cut (an imported mesh).
struct RankMesh {
  Eigen::MatrixXd nodes;  ///< the nodes its cells touch, in the mesh's order
  Eigen::MatrixXi cells;  ///< its cells on that numbering
  std::vector<int> node;  ///< the mesh node of each of `nodes`
  /// Whole on one process; on MPI ranks all its cells, {0, cells}: what they make is summed over
  /// the ranks (SvkSolidMesh's `held`).
  ColumnShare share;
  /// On MPI ranks: the model DOFs (ascending) its nodes' mesh DOFs need, and the rows of
  /// FeModel::mesh_map for those mesh DOFs on them.
  std::vector<int> model_rows;
  std::vector<int> row_owner;  ///< the rank that holds each of model_rows
  SparseMatrix map;
  /// On MPI ranks: the rank each node's sums go to (AddOnOwners): the one holding the model DOF
  /// its first mesh DOF maps from (rank 0 for a node that maps from none).
  std::vector<int> owner;
};
RankMesh RankMeshOf(const FeModel& model);

/// Fields X held as each rank's rows of the model's DOFs (model.columns) on the rank mesh's nodes
/// (3 per node): mesh_map X there, the model rows it needs fetched from the ranks that hold them
/// (FetchRows). mesh_map X on one process.
Eigen::MatrixXd RankMeshFields(const FeModel& model, const RankMesh& mesh, const Eigen::MatrixXd& X);

/// The solid's model on the ranks sharing a reduction: meshed and partitioned by rank 0 (a failure
/// there is every rank's: the others meet it where they wait for the mesh), reported as the stage
/// "mesh" by every rank once it has the mesh, then BuildSolidModelOn with the partition.
FeModel BuildSolidModelOnRanks(const PartSpec& part, const ProgressFn& progress);

}  // namespace femb
