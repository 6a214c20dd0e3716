// The readers behind ReadImportedMatrices (reducer/fe/matrix_files.h), one per format: each
// fills the DOF map (node labels and components 0..5 of the rows) and the 0-based entries of K
// and M as the files hold them (one triangle or both); matrix_files.cpp makes them symmetric and
// checks them. Every failure is an InputError naming the file and line.
#pragma once

#include <string>
#include <vector>

#include "formats/part_file.h"
#include "formats/text_lines.h"
#include "reducer/fe/matrix_files.h"

namespace femb {

struct MatrixEntry {
  long row, col;  ///< 0-based
  double value;
  long line;  ///< the file's line (0: not known)
};

/// An entry labelled by node and component (0..5) at both ends, as Abaqus' matrix input form
/// and Nastran's DMIG give them.
struct LabelledEntry {
  long node_i;
  int component_i;
  long node_j;
  int component_j;
  double value;
  long line;
};

/// Appends one row of a DOF map: node label and component 1..6 (else r.Fail).
void AddDof(const LineReader& r, long node, long c, ImportedMatrices* out);

/// "row column value" lines (1-based) up to the end of the file, into 0-based entries; an index
/// outside rows x cols fails naming `range`.
void ReadCoordinateEntries(LineReader* r, long rows, long cols, const std::string& range,
                           std::vector<MatrixEntry>* entries, const std::string& comment = "");

/// A Matrix Market file `coordinate real symmetric|general` of n x n whose rows the DOF map
/// `dofs` numbers.
void ReadMatrixMarketFile(const std::string& path, long n, const std::string& dofs, std::vector<MatrixEntry>* entries);

/// Labelled entries of K and M -> rows ordered by (node, component), into out's DOF map and the
/// 0-based entries.
void IndexLabelledEntries(const std::vector<LabelledEntry>& k_raw, const std::vector<LabelledEntry>& m_raw,
                          ImportedMatrices* out, std::vector<MatrixEntry>* k, std::vector<MatrixEntry>* m);

void ReadCalculix(const MatricesSpec& spec, ImportedMatrices* out, std::vector<MatrixEntry>* k,
                  std::vector<MatrixEntry>* m);
/// Abaqus' matrix input form, or the coordinate form when `coordinate` or its rows say so.
void ReadAbaqus(const MatricesSpec& spec, ImportedMatrices* out, std::vector<MatrixEntry>* k,
                std::vector<MatrixEntry>* m);
void ReadMatrixMarket(const MatricesSpec& spec, ImportedMatrices* out, std::vector<MatrixEntry>* k,
                      std::vector<MatrixEntry>* m);
/// Nastran DMIG entries (reducer/fe/nastran_ansys_matrices.cpp).
void ReadNastranDmig(const MatricesSpec& spec, ImportedMatrices* out, std::vector<MatrixEntry>* k,
                     std::vector<MatrixEntry>* m);
/// Ansys matrices (Matrix Market or Harwell-Boeing) with the HBMAT mapping file.
void ReadAnsys(const MatricesSpec& spec, ImportedMatrices* out, std::vector<MatrixEntry>* k,
               std::vector<MatrixEntry>* m);

}  // namespace femb
