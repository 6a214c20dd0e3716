// Dense matrices as text: Matrix Market (array, real, general) or CSV.
#pragma once

#include <Eigen/Core>
#include <ostream>
#include <string>

namespace femb {

/// Matrix Market "array real general" (column-major, full precision), with a comment line.
void WriteMatrixMarket(std::ostream& out, const Eigen::MatrixXd& A, const std::string& comment);

/// One row per line, comma separated, full precision (17 significant digits).
void WriteCsv(std::ostream& out, const Eigen::MatrixXd& A);

}  // namespace femb
