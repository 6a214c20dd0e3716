// Imported FE matrices (part type 'imported'): a model assembled by another FE code
// reduced by femb. The stiffness and mass come from files, the node coordinates (and node labels)
// from the geometry file through meshio; interfaces are named node sets of that file or nodes
// picked by geometry, tied by RBE2 or RBE3 as for femb's own solids.
//
// The matrix files and their formats: reducer/fe/matrix_files.h.
// Rotational DOFs (shells, beams) are allowed: an RBE2 node's rotations follow the interface's
// rotation; RBE3 uses the translations. The superelement file is an ordinary one (no stresses,
// no modal derivatives or geometric stiffening: those need femb's own elements).
#pragma once

#include <string>
#include <vector>

#include "formats/part_file.h"
#include "reducer/fe/fe_model.h"
#include "reducer/fe/matrix_files.h"
#include "reducer/progress.h"

namespace femb {

/// The model for Craig-Bampton: the imported matrices on the geometry's nodes with the couplings
/// of the part's interfaces folded in (RBE2: u_s = u_k + theta_k x (x_s - x_k), theta_s =
/// theta_k; RBE3 as a constraint). Checks that K leaves the rigid-body motions free (a grounded
/// spring or a boundary condition left in the export is one line). Reports geometry, matrices,
/// couplings.
FeModel BuildImportedModel(const PartSpec& part, const ProgressFn& progress = nullptr);

/// femb-reduce --export-matrices: the part's own assembled matrices before any coupling (solids:
/// 3 DOFs on every mesh node; beams: 6 per node) and its mesh as DIR/NAME.inp (Abaqus/CalculiX:
/// *NODE with labels 1..n, *ELEMENT, *NSET per named node set), so that a part file of type
/// 'imported' reads them back. Returns the paths written.
std::vector<std::string> ExportPartMatrices(const PartSpec& part, MatrixFormat format, const std::string& directory,
                                            const ProgressFn& progress = nullptr);

}  // namespace femb
