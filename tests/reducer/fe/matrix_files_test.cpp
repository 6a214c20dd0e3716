// Matrix files of other FE codes (reducer/fe/matrix_files.h): what WriteMatrices writes in each
// format, ReadImportedMatrices reads back to the bit (17 significant digits), on node labels
// that are neither contiguous nor from 1 and a node with translations only; damaged files stop
// with one line naming the file and the line.
#include "reducer/fe/matrix_files.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "test_util.h"

namespace femb {
namespace {

namespace fs = std::filesystem;

// A symmetric positive definite matrix on n rows with a banded pattern and values of full precision.
SparseMatrix RandomSpd(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = i; j < std::min(n, i + 4); ++j) A(i, j) = A(j, i) = (i == j ? 10.0 : 1.0) * (u(rng) + 1.5) * 3.7e5;
  return A.sparseView();
}

struct Case {
  std::vector<long> node;
  std::vector<int> component;
  SparseMatrix K, M;
};

// Nodes 7 and 40 with six DOFs, node 12 with translations only; rows by (node, component).
Case MakeCase() {
  Case c;
  for (long n : {7L, 12L, 40L}) {
    for (int k = 0; k < (n == 12 ? 3 : 6); ++k) {
      c.node.push_back(n);
      c.component.push_back(k);
    }
  }
  const int rows = int(c.node.size());
  c.K = RandomSpd(rows, 1);
  c.M = RandomSpd(rows, 2) * 1e-9;
  return c;
}

fs::path TempDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("femb_matrix_files_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

MatricesSpec SpecFor(MatrixFormat format, const fs::path& dir) {
  MatricesSpec spec;
  spec.format = format;
  spec.where = "part.yaml:4: matrices";
  if (format == MatrixFormat::kCalculix) {
    spec.stiffness = (dir / "m.sti").string();
    spec.mass = (dir / "m.mas").string();
    spec.dofs = (dir / "m.dof").string();
  } else if (format == MatrixFormat::kAbaqus) {
    spec.stiffness = (dir / "m_STIF1.mtx").string();
    spec.mass = (dir / "m_MASS1.mtx").string();
  } else {
    spec.stiffness = (dir / "m_K.mtx").string();
    spec.mass = (dir / "m_M.mtx").string();
    spec.dofs = (dir / "m_dofs.csv").string();
  }
  return spec;
}

TEST(MatrixFiles, EveryFormatReadsBackWhatWasWrittenToTheBit) {
  const Case c = MakeCase();
  for (MatrixFormat format : {MatrixFormat::kCalculix, MatrixFormat::kAbaqus, MatrixFormat::kMatrixMarket}) {
    SCOPED_TRACE(Name(format));
    const fs::path dir = TempDir(Name(format));
    const std::vector<std::string> written = WriteMatrices(format, c.K, c.M, c.node, c.component, dir.string(), "m");
    EXPECT_EQ(written.size(), format == MatrixFormat::kAbaqus ? 2u : 3u);
    const ImportedMatrices read = ReadImportedMatrices(SpecFor(format, dir));
    EXPECT_EQ(read.node, c.node);
    EXPECT_EQ(read.component, c.component);
    // Matrix Market's symmetric storage is the lower triangle; the others write the upper one.
    EXPECT_EQ(read.stored, format == MatrixFormat::kMatrixMarket ? "lower triangle" : "upper triangle");
    EXPECT_EQ((Eigen::MatrixXd(read.K) - Eigen::MatrixXd(c.K)).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ((Eigen::MatrixXd(read.M) - Eigen::MatrixXd(c.M)).cwiseAbs().maxCoeff(), 0.0);
    fs::remove_all(dir);
  }
}

TEST(MatrixFiles, ADamagedFileIsNamedWithItsLine) {
  const Case c = MakeCase();
  const fs::path dir = TempDir("damaged");
  WriteMatrices(MatrixFormat::kCalculix, c.K, c.M, c.node, c.component, dir.string(), "m");
  const MatricesSpec spec = SpecFor(MatrixFormat::kCalculix, dir);
  // Line 3 of the stiffness file no longer holds a number.
  std::vector<std::string> lines;
  {
    std::ifstream in(spec.stiffness);
    for (std::string line; std::getline(in, line);) lines.push_back(line);
  }
  ASSERT_GT(lines.size(), 3u);
  const std::string kept = lines[2];
  lines[2] = "1 3 abc";
  {
    std::ofstream out(spec.stiffness);
    for (const std::string& line : lines) out << line << '\n';
  }
  const std::string message = test::ThrownMessage([&] { ReadImportedMatrices(spec); });
  EXPECT_NE(message.find(spec.stiffness + ":3"), std::string::npos) << message;
  // A negative stiffness on the diagonal of the first DOF (the line "1 1 ..." restored first).
  lines[2] = kept;
  for (std::string& line : lines) {
    if (line.rfind("1 1 ", 0) == 0) line = "1 1 -5.0";
  }
  {
    std::ofstream out(spec.stiffness);
    for (const std::string& line : lines) out << line << '\n';
  }
  const std::string negative = test::ThrownMessage([&] { ReadImportedMatrices(spec); });
  EXPECT_NE(negative.find(spec.stiffness), std::string::npos) << negative;
  EXPECT_NE(negative.find("negative"), std::string::npos) << negative;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace femb
