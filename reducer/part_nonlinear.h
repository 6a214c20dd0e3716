// The part's geometrically nonlinear model (reduce_part.cpp): the Green-Lagrange solid (solids,
// imported meshes) or von Karman beams for the modal derivatives' loads and the geometric
// stiffening, on MPI ranks a solid's on each rank's own cells (RankMesh, solid_ranks.h).
#pragma once

#include <memory>

#include "formats/part_file.h"
#include "reducer/fe/fe_model.h"
#include "reducer/fe/nonlinear_solid.h"
#include "reducer/fe/solid_ranks.h"
#include "reducer/reduction/craig_bampton.h"

namespace femb {

/// The solid element type of a cell type; InputError for a cell femb has no solid for.
SolidType SolidCellType(CellType cell);

/// The Green-Lagrange (solids, imported meshes) or von Karman (beams) model of the part, built on
/// first use for the modal derivatives and the geometric stiffening, and the map from the FE
/// model's DOFs to its own (its DOFs = to_model_dofs() x the model's). On MPI ranks a solid's
/// element loops take this rank's cells (Mesh, OnRankMesh).
class NonlinearModelOf {
 public:
  NonlinearModelOf(const PartSpec& part, const FeModel& model)
      : part_(part), model_(model), to_model_dofs_(model.mesh_map) {}
  /// The model on the whole mesh (every rank's the same).
  const NonlinearModel& Get();
  bool built() const { return nonlinear_ || rank_solid_; }
  const SparseMatrix& to_model_dofs() const { return to_model_dofs_; }
  /// A solid's cells this rank takes in the loops over the elements, built on first use
  /// (RankMeshOf: all of them on one process).
  const RankMesh& Mesh();
  /// A solid's Green-Lagrange model on those cells: Get() on one process.
  const SvkSolidMesh& OnRankMesh();

 private:
  const PartSpec& part_;
  const FeModel& model_;
  std::unique_ptr<NonlinearModel> nonlinear_;
  std::unique_ptr<RankMesh> rank_mesh_;
  std::unique_ptr<SvkSolidMesh> rank_solid_;
  SparseMatrix to_model_dofs_;
};

/// The modal derivatives the part asks for (none when it asks for none): the pairs of
/// Craig-Bampton coordinates and dK/dq on them from `nonlinear` (the request refers to it and to
/// `model`).
DerivativeRequest ModalDerivativeRequest(const PartSpec& part, const FeModel& model, NonlinearModelOf& nonlinear);

}  // namespace femb
