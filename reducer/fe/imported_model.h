// Imported FE matrices (issue 16, part type 'imported'): a model assembled by another FE code
// reduced by femb. The stiffness and mass come from files, the node coordinates (and node labels)
// from the geometry file through meshio; interfaces are named node sets of that file or nodes
// picked by geometry, tied by RBE2 or RBE3 as for femb's own solids.
//
// Formats (symmetric; one triangle or both, both then checked to 1e-8 of the largest entry):
//   calculix       *FREQUENCY, SOLVER=MATRIXSTORAGE (CalculiX 2.20): job.sti and job.mas hold
//                  "row col value" (1-based, upper triangle), job.dof one "node.component" per row
//   abaqus         *MATRIX GENERATE + *MATRIX OUTPUT (default, matrix input format):
//                  "row node, row dof, column node, column dof, value"; rows numbered by
//                  (node, dof) ascending
//   matrix_market  coordinate real symmetric|general (any tool; e.g. scipy.io.mmwrite), with a
//                  CSV "node, component" per row (component 1..6 = u_x, u_y, u_z, th_x, th_y, th_z)
// Rotational DOFs (shells, beams) are allowed: an RBE2 node's rotations follow the interface's
// rotation; RBE3 uses the translations. The superelement file is an ordinary one (no stresses,
// no modal derivatives or geometric stiffening: those need femb's own elements).
#pragma once

#include <string>
#include <vector>

#include "formats/part_file.h"
#include "reducer/fe/fe_model.h"
#include "reducer/progress.h"

namespace femb {

/// K and M on the imported DOFs, row r being component `component[r]` (0..5) of node label
/// `node[r]`. Both triangles stored.
struct ImportedMatrices {
  std::vector<long> node;
  std::vector<int> component;
  SparseMatrix K, M;
  std::string stored;  ///< "upper triangle", "lower triangle" or "both triangles" (of K)
};

/// Reads and checks the matrices of `spec`: every entry's file and line on failure (unreadable,
/// not a number, not finite, index out of range, asymmetric beyond 1e-8, negative diagonal, a
/// DOF without stiffness, the same node and component twice). Throws InputError.
ImportedMatrices ReadImportedMatrices(const MatricesSpec& spec);

/// The model for Craig-Bampton: the imported matrices on the geometry's nodes with the couplings
/// of the part's interfaces folded in (RBE2: u_s = u_k + theta_k x (x_s - x_k), theta_s =
/// theta_k; RBE3 as a constraint). Checks that K leaves the rigid-body motions free (a grounded
/// spring or a boundary condition left in the export is one line). Reports geometry, matrices,
/// couplings.
FeModel BuildImportedModel(const PartSpec& part, const ProgressFn& progress = nullptr);

/// Deformation shapes on the imported DOFs (reduction.method general): a Matrix Market file,
/// `array real general` (column by column) or `coordinate real general`, `rows` x shapes.
/// Throws InputError naming the file and line.
Eigen::MatrixXd ReadShapeMatrix(const std::string& path, long rows);

/// Writes K and M (both triangles given; the upper one is written) in `format` for the DOFs
/// (node label, component 0..5): calculix -> DIR/STEM.sti, .mas, .dof; abaqus ->
/// DIR/STEM_STIF1.mtx, DIR/STEM_MASS1.mtx; matrix_market -> DIR/STEM_K.mtx, DIR/STEM_M.mtx,
/// DIR/STEM_dofs.csv. Returns the paths written. Throws InputError when DIR cannot be written.
std::vector<std::string> WriteMatrices(const std::string& format, const SparseMatrix& K, const SparseMatrix& M,
                                       const std::vector<long>& node, const std::vector<int>& component,
                                       const std::string& directory, const std::string& stem);

/// femb-reduce --export-matrices: the part's own assembled matrices before any coupling (solids:
/// 3 DOFs on every mesh node; beams: 6 per node) and its mesh as DIR/NAME.inp (Abaqus/CalculiX:
/// *NODE with labels 1..n, *ELEMENT, *NSET per named node set), so that a part file of type
/// 'imported' reads them back. Returns the paths written.
std::vector<std::string> ExportPartMatrices(const PartSpec& part, const std::string& format,
                                            const std::string& directory, const ProgressFn& progress = nullptr);

}  // namespace femb
