// FE matrix files of other codes: readers with every check femb makes on load, and
// the writer of femb-reduce --export-matrices. Formats (symmetric; one triangle or both, both
// then checked to 1e-8 of the largest entry):
//   calculix       *FREQUENCY, SOLVER=MATRIXSTORAGE (CalculiX 2.20): job.sti and job.mas hold
//                  "row col value" (1-based, upper triangle), job.dof one "node.component" per row
//   abaqus         *MATRIX GENERATE + *MATRIX OUTPUT: the matrix input form "row node, row dof,
//                  column node, column dof, value", rows numbered by (node, dof) ascending; or
//                  FORMAT=COORDINATE "row column value" on the equations the deck numbers
//                  (formats/abaqus_deck.h), recognized by its rows (abaqus_coordinate: always)
//   matrix_market  coordinate real symmetric|general (any tool; e.g. scipy.io.mmwrite), with a
//                  CSV "node, component" per row (component 1..6 = u_x, u_y, u_z, th_x, th_y, th_z)
//   nastran        DMIG entries (small, large or free field); rows are (grid, component)
//   ansys          HBMAT's Harwell-Boeing or *EXPORT's Matrix Market, with HBMAT's mapping file
// The readers are in reducer/fe/matrix_readers.h. These depend on the formats library alone
// (tests/fuzz/matrix_fuzz.cpp builds them by themselves).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "formats/part_file.h"
#include "reducer/fe/fe_model.h"

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

/// Deformation shapes on the imported DOFs (reduction.method general): a Matrix Market file,
/// `array real general` (column by column) or `coordinate real general`, `rows` x shapes.
/// Throws InputError naming the file and line.
Eigen::MatrixXd ReadShapeMatrix(const std::string& path, long rows);

/// Writes K and M (both triangles given) in `format` for the DOFs (node label, component 0..5):
/// calculix -> DIR/STEM.sti, .mas, .dof; abaqus -> DIR/STEM_STIF1.mtx, DIR/STEM_MASS1.mtx;
/// abaqus_coordinate -> the same files as "row column value" on the rows' order (the equation
/// numbers of a deck whose nodes carry these DOFs); matrix_market -> DIR/STEM_K.mtx,
/// DIR/STEM_M.mtx, DIR/STEM_dofs.csv. The upper triangle is written, both for abaqus_coordinate;
/// nastran and ansys are read only. Returns the paths written. Throws InputError when DIR cannot
/// be written.
std::vector<std::string> WriteMatrices(MatrixFormat format, const SparseMatrix& K, const SparseMatrix& M,
                                       const std::vector<long>& node, const std::vector<int>& component,
                                       const std::string& directory, const std::string& stem);

/// A number in 3 significant digits, for messages.
std::string ShortNumber(double v);

}  // namespace femb
