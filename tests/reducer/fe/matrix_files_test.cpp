// Matrix files of other FE codes (reducer/fe/matrix_files.h): what WriteMatrices writes in each
// format, ReadImportedMatrices reads back to the bit (17 significant digits), on node labels
// that are neither contiguous nor from 1 and a node with translations only; damaged files stop
// with one line naming the file and the line.
#include "reducer/fe/matrix_files.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <charconv>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <random>
#include <string>
#include <tuple>
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

// The shortest decimal text of v, with Nastran's exponent without a letter (4.001-6).
std::string NastranText(double v) {
  char b[64];
  const auto [end, ec] = std::to_chars(b, b + sizeof b, v);
  std::string t(b, end);
  const size_t e = t.find('e');
  if (e == std::string::npos) return t.find('.') == std::string::npos ? t + "." : t;
  std::string mantissa = t.substr(0, e), exponent = t.substr(e + 1);
  if (mantissa.find('.') == std::string::npos) mantissa += ".";
  const char sign = exponent[0] == '-' ? '-' : '+';
  exponent = exponent.substr(exponent[0] == '-' || exponent[0] == '+' ? 1 : 0);
  exponent.erase(0, std::min(exponent.find_first_not_of('0'), exponent.size() - 1));
  return mantissa + sign + exponent;
}

// Nastran's DMIG entries for Bar-2, written by hand to the Quick Reference Guide: the header in
// small field; each column of K (lower triangle, as punched) in small field where its values fit
// eight characters, else in large field (DMIG* and *); M in free field.
void WriteBarDmig(const fs::path& path) {
  std::ofstream out(path);
  auto field8 = [](const std::string& s, bool right) {
    std::string f =
        s.size() >= 8 ? s : (right ? std::string(8 - s.size(), ' ') + s : s + std::string(8 - s.size(), ' '));
    return f;
  };
  auto field16 = [](const std::string& s) { return s + std::string(16 - s.size(), ' '); };
  out << "$ hand-written DMIG: KAAX in small and large field, MAAX in free field\n";
  out << "DMIG    KAAX           0       6       2       0\n";
  out << "DMIG,MAAX,0,6,2,0\n";
  for (int j = 0; j < 9; ++j) {
    std::vector<std::tuple<int, int, std::string, std::string>> rows;  // node, component, K, M
    for (int i : {j, j + 3})
      if (i < 9)
        rows.emplace_back(i / 3 + 1, i % 3 + 1, NastranText(BarEntry(i, j, 0.0)),
                          NastranText(1e-6 * BarEntry(i, j, 0.0)));
    bool small = true;
    for (const auto& row : rows) small = small && std::get<2>(row).size() <= 8;
    const std::string gj = std::to_string(j / 3 + 1), cj = std::to_string(j % 3 + 1);
    if (small) {
      out << "DMIG    " << field8("KAAX", false) << field8(gj, true) << field8(cj, false) << field8("", false);
      for (size_t r = 0; r < rows.size(); ++r) {
        if (r == 1) out << "\n+       ";
        out << field8(std::to_string(std::get<0>(rows[r])), true) << field8(std::to_string(std::get<1>(rows[r])), true)
            << field8(std::get<2>(rows[r]), false) << (r == 0 ? field8("", false) : "");
      }
      out << "\n";
    } else {
      out << "DMIG*   " << field16("KAAX") << field16(gj) << field16(cj) << field16("") << "\n";
      for (const auto& row : rows)
        out << "*       " << field16(std::to_string(std::get<0>(row))) << field16(std::to_string(std::get<1>(row)))
            << field16(std::get<2>(row)) << "\n";
    }
    out << "DMIG,MAAX," << gj << "," << cj << ",";
    for (size_t r = 0; r < rows.size(); ++r) {
      if (r == 1) out << ",\n+";
      out << "," << std::get<0>(rows[r]) << "," << std::get<1>(rows[r]) << "," << std::get<3>(rows[r]);
    }
    out << "\n";
  }
}

// Ansys' HBMAT output for Bar-2 written by hand to the Harwell-Boeing layout (RSA: the lower
// triangle by columns; 10 pointers or indices of 8 characters and 3 values of 26 per line), with
// the mapping file HBMAT writes beside it.
void WriteBarAnsys(const fs::path& dir) {
  std::ofstream map(dir / "bar.mapping");
  map << " Matrix Eqn   Node   DOF\n";
  const char* labels[3] = {"UX", "UY", "UZ"};
  for (int i = 0; i < 9; ++i)
    map << std::setw(8) << i + 1 << std::setw(8) << i / 3 + 1 << "     " << labels[i % 3] << '\n';
  for (const auto& [name, scale] : {std::pair{"K.matrix", 1.0}, std::pair{"M.matrix", 1e-6}}) {
    std::vector<int> pointer{1}, index;
    std::vector<double> value;
    for (int j = 0; j < 9; ++j) {
      for (int i : {j, j + 3})
        if (i < 9) {
          index.push_back(i + 1);
          value.push_back(scale * BarEntry(i, j, 0.0));
        }
      pointer.push_back(int(index.size()) + 1);
    }
    auto lines = [](size_t n, size_t per) { return (n + per - 1) / per; };
    std::ofstream out(dir / name);
    char b[128];
    std::snprintf(b, sizeof b, "%-72s%-8s\n", "bar written by hand as HBMAT does", "KEY");
    out << b;
    const size_t p = lines(pointer.size(), 10), q = lines(index.size(), 10), v = lines(value.size(), 3);
    std::snprintf(b, sizeof b, "%14zu%14zu%14zu%14zu%14d\n", p + q + v, p, q, v, 0);
    out << b;
    std::snprintf(b, sizeof b, "RSA           %14d%14d%14zu%14d\n", 9, 9, index.size(), 0);
    out << b;
    std::snprintf(b, sizeof b, "%-16s%-16s%-20s%-20s\n", "(10I8)", "(10I8)", "(3E26.16)", "");
    out << b;
    for (const std::vector<int>* block : {&pointer, &index})
      for (size_t k = 0; k < block->size(); ++k)
        out << std::setw(8) << (*block)[k] << (k % 10 == 9 || k + 1 == block->size() ? "\n" : "");
    for (size_t k = 0; k < value.size(); ++k) {
      std::snprintf(b, sizeof b, "%26.16E", value[k]);
      out << b << (k % 3 == 2 || k + 1 == value.size() ? "\n" : "");
    }
  }
}

TEST(MatrixFiles, NastranDmigAndAnsysHarwellBoeingGiveTheSameMatricesToTheBit) {
  const HandWritten h = WriteBarForms("nastran_ansys");
  const ImportedMatrices reference = ReadImportedMatrices(h.labels);
  WriteBarDmig(h.dir / "bar.pch");
  WriteBarAnsys(h.dir);
  MatricesSpec dmig;
  dmig.format = MatrixFormat::kNastran;
  dmig.where = "part.yaml:4: matrices";
  dmig.stiffness = dmig.mass = (h.dir / "bar.pch").string();
  MatricesSpec ansys = dmig;
  ansys.format = MatrixFormat::kAnsys;
  ansys.stiffness = (h.dir / "K.matrix").string();
  ansys.mass = (h.dir / "M.matrix").string();
  ansys.dofs = (h.dir / "bar.mapping").string();
  MatricesSpec ansys_mm = ansys;  // *EXPORT,,MMF with the same mapping
  ansys_mm.stiffness = h.market.stiffness;
  ansys_mm.mass = h.market.mass;
  for (const MatricesSpec& spec : {dmig, ansys, ansys_mm}) {
    SCOPED_TRACE(spec.stiffness);
    const ImportedMatrices read = ReadImportedMatrices(spec);
    EXPECT_EQ(read.node, reference.node);
    EXPECT_EQ(read.component, reference.component);
    EXPECT_EQ((Eigen::MatrixXd(read.K) - Eigen::MatrixXd(reference.K)).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ((Eigen::MatrixXd(read.M) - Eigen::MatrixXd(reference.M)).cwiseAbs().maxCoeff(), 0.0);
  }
  EXPECT_EQ(ReadImportedMatrices(dmig).stored, "lower triangle");
  fs::remove_all(h.dir);
}

TEST(MatrixFiles, BadNastranAndAnsysFilesAreOneLine) {
  const fs::path dir = TempDir("nastran_ansys_bad");
  auto read = [&](MatrixFormat format, const std::string& k, const std::string& m, const std::string& map = "") {
    std::ofstream(dir / "k.txt") << k;
    std::ofstream(dir / "m.txt") << m;
    std::ofstream(dir / "map.txt") << map;
    MatricesSpec spec;
    spec.format = format;
    spec.where = "part.yaml:4: matrices";
    spec.stiffness = (dir / "k.txt").string();
    spec.mass = (dir / "m.txt").string();
    spec.dofs = (dir / "map.txt").string();
    const std::string message = test::ThrownMessage([&] { ReadImportedMatrices(spec); });
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    return message;
  };
  auto has = [](const std::string& m, const std::string& part) { EXPECT_NE(m.find(part), std::string::npos) << m; };
  const std::string header = "DMIG,KAAX,0,6,2,0\n", mass = "DMIG,MAAX,0,6,2,0\nDMIG,MAAX,1,1,,1,1,1.0\n";
  has(read(MatrixFormat::kNastran, "DMIG,KAAX,1,1,,1,1,1.0\n", mass),
      "k.txt:1: DMIG KAAX has a column before its header");
  has(read(MatrixFormat::kNastran, header + "DMIG,KAAX,1,1,,1,0,1.0\n", mass), "k.txt:2: component '0' of point 1");
  has(read(MatrixFormat::kNastran, header + "DMIG,KAAX,1,1,,1,1,abc\n", mass), "k.txt:2: 'abc' is not a finite number");
  has(read(MatrixFormat::kNastran, "DMIG,KAAX,0,9,2,0,,,3\n", mass), "has IFO '9'");
  has(read(MatrixFormat::kNastran, "DMIG,KAAX,0,6,3,0\n", mass), "has TIN '3'");
  has(read(MatrixFormat::kNastran, header + "DMIG,KBBX,0,6,2,0\n", mass),
      "DMIG matrices KAAX, KBBX: expected one stiffness matrix");
  const std::string map = " Matrix Eqn   Node   DOF\n 1 1 UX\n 2 1 UY\n";
  const std::string mm = "%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n1 1 1.0\n2 2 1.0\n";
  has(read(MatrixFormat::kAnsys, mm, mm, " Matrix Eqn   Node   DOF\n 1 1 UX\n 2 1 TEMP\n"),
      "map.txt:3: DOF label 'TEMP'");
  has(read(MatrixFormat::kAnsys, mm, mm, " Matrix Eqn   Node   DOF\n 1 1 UX\n 3 1 UY\n"),
      "map.txt:3: equation 3 where 2 comes next");
  has(read(MatrixFormat::kAnsys, mm, mm, " Matrix Eqn   Node   DOF\n 1 1 UX\n"), "the matrix has 2 rows but");
  has(read(MatrixFormat::kAnsys, mm, mm, " Matrix Eqn   Node   DOF\n 1 1 UX\n,,,\n"),
      "map.txt:3: expected 'equation node label'");
  has(read(MatrixFormat::kAnsys, "title\n 4 1 1 1 0\nCSA            2 2 2 0\n(10I8) (10I8) (3E26.16)\n", mm, map),
      "matrix type 'CSA'");
  has(read(MatrixFormat::kAnsys,
           "title\n 4 1 1 1 0\nRSA                        2             2             2             0\n"
           "(10I8)          (10I8)          (3E26.16)\n       1       2       4\n       1       2\n 1.0\n 1.0\n",
           mm, map),
      "column pointer 2 is not increasing");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace femb
