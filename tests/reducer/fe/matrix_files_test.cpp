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

// Two instances of a three-node bar (T3D2 elements: three DOFs per node, nine equations per
// instance), written by hand as Abaqus documents each form: the coordinate form numbers the 18
// equations instance by instance, node by node; the matrix input form labels node and DOF; Matrix
// Market with its DOF map. Instance Bar-2's matrices read from each are the same to the bit.
constexpr const char* kBarDeck = R"(*Part, name=Bar
*Node
1, 0., 0., 0.
2, 1., 0., 0.
3, 2., 0., 0.
*Element, type=T3D2
1, 1, 2
2, 2, 3
*End Part
*Assembly, name=Assembly
*Instance, name=Bar-1, part=Bar
*End Instance
*Instance, name=Bar-2, part=Bar
 0., 1., 0.
*End Instance
*End Assembly
)";

// The bar's K (or M, scaled) on its nine DOFs: a diagonal and each node's DOF coupled to the
// next node's same DOF; `shift` changes the values per instance.
double BarEntry(int i, int j, double shift) {
  if (i == j) return 4.0e6 + 1000.0 * i + shift;
  return -1.0e6 - 10.0 * std::min(i, j) - shift;
}

struct HandWritten {
  fs::path dir;
  MatricesSpec coordinate, labels, market;
};

HandWritten WriteBarForms(const std::string& name) {
  HandWritten h;
  h.dir = TempDir(name);
  std::ofstream(h.dir / "bar.inp") << kBarDeck;
  std::ofstream kc(h.dir / "c_STIF1.mtx"), mc(h.dir / "c_MASS1.mtx");
  std::ofstream kl(h.dir / "l_STIF1.mtx"), ml(h.dir / "l_MASS1.mtx");
  std::ofstream km(h.dir / "K.mtx"), mm(h.dir / "M.mtx"), map(h.dir / "dofs.csv");
  kc.precision(17);
  mc.precision(17);
  kl.precision(17);
  ml.precision(17);
  km.precision(17);
  mm.precision(17);
  km << "%%MatrixMarket matrix coordinate real symmetric\n9 9 15\n";
  mm << "%%MatrixMarket matrix coordinate real symmetric\n9 9 15\n";
  map << "node,component\n";
  for (int i = 0; i < 9; ++i) map << i / 3 + 1 << ", " << i % 3 + 1 << '\n';
  for (int instance = 0; instance < 2; ++instance) {
    const double shift = instance == 0 ? 777.0 : 0.0;  // Bar-1 differs: its rows must be dropped
    for (int j = 0; j < 9; ++j)
      for (int i : {j - 3, j}) {  // upper triangle, column by column
        if (i < 0) continue;
        const double k = BarEntry(i, j, shift), m = 1e-6 * BarEntry(i, j, shift);
        kc << 9 * instance + i + 1 << ' ' << 9 * instance + j + 1 << "  " << k << '\n';
        mc << 9 * instance + i + 1 << ' ' << 9 * instance + j + 1 << "  " << m << '\n';
        if (instance == 0) continue;
        kl << i / 3 + 1 << ", " << i % 3 + 1 << ", " << j / 3 + 1 << ", " << j % 3 + 1 << ", " << k << '\n';
        ml << i / 3 + 1 << ", " << i % 3 + 1 << ", " << j / 3 + 1 << ", " << j % 3 + 1 << ", " << m << '\n';
        km << j + 1 << ' ' << i + 1 << ' ' << k << '\n';
        mm << j + 1 << ' ' << i + 1 << ' ' << m << '\n';
      }
  }
  auto spec = [&](MatrixFormat format, const std::string& k, const std::string& m, const std::string& dofs) {
    MatricesSpec s;
    s.format = format;
    s.where = "part.yaml:4: matrices";
    s.stiffness = (h.dir / k).string();
    s.mass = (h.dir / m).string();
    if (!dofs.empty()) s.dofs = (h.dir / dofs).string();
    s.deck = (h.dir / "bar.inp").string();
    s.instance = "Bar-2";
    return s;
  };
  h.coordinate = spec(MatrixFormat::kAbaqus, "c_STIF1.mtx", "c_MASS1.mtx", "");
  h.labels = spec(MatrixFormat::kAbaqus, "l_STIF1.mtx", "l_MASS1.mtx", "");
  h.market = spec(MatrixFormat::kMatrixMarket, "K.mtx", "M.mtx", "dofs.csv");
  return h;
}

TEST(MatrixFiles, AbaqusCoordinateFormMatchesTheLabelledFormsToTheBit) {
  const HandWritten h = WriteBarForms("coordinate");
  const ImportedMatrices c = ReadImportedMatrices(h.coordinate);
  MatricesSpec forced = h.coordinate;
  forced.format = MatrixFormat::kAbaqusCoordinate;
  for (const ImportedMatrices& other :
       {ReadImportedMatrices(h.labels), ReadImportedMatrices(h.market), ReadImportedMatrices(forced)}) {
    EXPECT_EQ(c.node, other.node);
    EXPECT_EQ(c.component, other.component);
    EXPECT_EQ((Eigen::MatrixXd(c.K) - Eigen::MatrixXd(other.K)).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ((Eigen::MatrixXd(c.M) - Eigen::MatrixXd(other.M)).cwiseAbs().maxCoeff(), 0.0);
  }
  EXPECT_EQ(c.node, (std::vector<long>{1, 1, 1, 2, 2, 2, 3, 3, 3}));
  EXPECT_EQ(c.K.coeff(0, 0), BarEntry(0, 0, 0.0));  // Bar-2's values, not Bar-1's
  EXPECT_EQ(c.stored, "upper triangle");
  fs::remove_all(h.dir);
}

TEST(MatrixFiles, AbaqusCoordinateFormThatDoesNotFitTheDeckIsOneLine) {
  const HandWritten h = WriteBarForms("coordinate_bad");
  auto message = [&](const std::string& extra, const std::string& instance = "Bar-2", bool deck = true) {
    std::ofstream(h.coordinate.stiffness, std::ios::app) << extra;
    MatricesSpec spec = h.coordinate;
    spec.instance = instance;
    if (!deck) spec.deck.clear();
    const std::string m = test::ThrownMessage([&] { ReadImportedMatrices(spec); });
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    return m;
  };
  auto has = [](const std::string& m, const std::string& part) { EXPECT_NE(m.find(part), std::string::npos) << m; };
  has(message("", ""), "has 2 instances (Bar-1, Bar-2): name one with matrices.instance");
  has(message("", "Bar-9"), "has no instance 'Bar-9'");
  has(message("", "Bar-2", false), "numbers equations, not nodes");
  has(message("9 10  5.0\n"), "c_STIF1.mtx:31: the entry couples instance Bar-2 to node 3 of instance Bar-1");
  fs::remove_all(h.dir);
  const HandWritten g = WriteBarForms("coordinate_count");
  std::ofstream(g.coordinate.stiffness, std::ios::app) << "19 19  5.0\n";
  has(test::ThrownMessage([&] { ReadImportedMatrices(g.coordinate); }),
      "c_STIF1.mtx:31: equation 19 is outside 1..18 (the deck's nodes and elements give 18 equations; Abaqus adds");
  fs::remove_all(g.dir);
}

}  // namespace
}  // namespace femb
