#include "formats/matrix_text.h"

#include <cstdio>

namespace femb {
namespace {
std::string Full(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", v);
  return buffer;
}
}  // namespace

void WriteMatrixMarket(std::ostream& out, const Eigen::MatrixXd& A, const std::string& comment) {
  out << "%%MatrixMarket matrix array real general\n";
  if (!comment.empty()) out << "% " << comment << "\n";
  out << A.rows() << " " << A.cols() << "\n";
  for (Eigen::Index j = 0; j < A.cols(); ++j) {
    for (Eigen::Index i = 0; i < A.rows(); ++i) out << Full(A(i, j)) << "\n";
  }
}

void WriteCsv(std::ostream& out, const Eigen::MatrixXd& A) {
  for (Eigen::Index i = 0; i < A.rows(); ++i) {
    for (Eigen::Index j = 0; j < A.cols(); ++j) out << (j ? "," : "") << Full(A(i, j));
    out << "\n";
  }
}

}  // namespace femb
