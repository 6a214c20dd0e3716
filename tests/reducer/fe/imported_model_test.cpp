// Imported FE matrices: a native part exported by femb-reduce's exporter in each
// matrix format and read back as a part of type 'imported' reduces to the same superelement
// (frequencies and reduced matrices to 1e-8 of the native part's, K_r, the static block of M_r
// and the frequencies to 1e-12 of each other); a beam with rotational DOFs too; CalculiX's own
// assembly of the same mesh agrees within the element-quadrature difference; bad matrices are
// one line each, naming the file and line or the DOF.
#include "reducer/fe/imported_model.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Dense>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include "formats/superelement_checks.h"
#include "reducer/reduce_part.h"
#include "test_util.h"

namespace femb {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("femb_imported_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void WriteText(const fs::path& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

std::string ReadText(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

Superelement ReduceFile(const fs::path& part) {
  const PartSpec spec = ReadPartFile(part.string());
  ReduceResult r = ReducePart(spec, nullptr);
  EXPECT_TRUE(r.ok) << r.message;
  return r.superelement;
}

double Relative(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) { return (a - b).norm() / b.norm(); }

const char* kBar =
    "name: bar\ntype: solid\nmaterial: {E: 2.1e11, nu: 0.3, rho: 7850}\n"
    "geometry: {shape: box, size: [1.0, 0.05, 0.05]}\nmesh: {size: 0.05, order: 2}\n"
    "interfaces: [{name: root, group: xmin}, {name: tip, group: xmax, coupling: rbe3}]\n"
    "reduction: {internal_modes: 6}\n";

// The matrices block of an imported part for the files the exporter wrote.
std::string MatricesBlock(const std::string& format, const std::string& dir) {
  if (format == "calculix") {
    return "{format: calculix, stiffness: " + dir + "/bar.sti, mass: " + dir + "/bar.mas, dofs: " + dir + "/bar.dof}";
  }
  // Both Abaqus forms as `format: abaqus`: the coordinate form is recognized by its rows.
  if (format == "abaqus" || format == "abaqus_coordinate")
    return "{format: abaqus, stiffness: " + dir + "/bar_STIF1.mtx, mass: " + dir + "/bar_MASS1.mtx}";
  return "{format: matrix_market, stiffness: " + dir + "/bar_K.mtx, mass: " + dir + "/bar_M.mtx, dofs: " + dir +
         "/bar_dofs.csv}";
}

TEST(ImportedModel, EveryFormatRoundTripsToTheNativeSuperelement) {
  const fs::path dir = TempDir("formats");
  WriteText(dir / "bar.yaml", kBar);
  const PartSpec part = ReadPartFile((dir / "bar.yaml").string());
  // The native reference on the exported mesh (the same nodes in the same order).
  WriteText(dir / "native.yaml",
            test::Replace(kBar, "{shape: box, size: [1.0, 0.05, 0.05]}", "{file: calculix/bar.inp}"));
  for (const std::string format : {"calculix", "abaqus", "abaqus_coordinate", "matrix_market"}) {
    ExportPartMatrices(part, *KindOf<MatrixFormat>(format), (dir / format).string());
  }
  const Superelement native = ReduceFile(dir / "native.yaml");
  std::optional<Superelement> first;  // the CalculiX files' superelement
  for (const std::string format : {"calculix", "abaqus", "abaqus_coordinate", "matrix_market"}) {
    WriteText(dir / "imported.yaml",
              "name: bar\ntype: imported\ngeometry: {file: " + format +
                  "/bar.inp}\nmatrices: " + MatricesBlock(format, format) +
                  "\ninterfaces: [{name: root, group: xmin}, {name: tip, group: xmax, coupling: rbe3}]\n"
                  "reduction: {internal_modes: 6}\n");
    const Superelement imported = ReduceFile(dir / "imported.yaml");
    ASSERT_EQ(imported.K.rows(), native.K.rows()) << format;
    // The fixed-interface modes are unique up to sign (and to a turn within the square bar's
    // nearly equal bending pairs): compare what is unique - the frequencies, K_r, the static
    // modes' block of M_r and their shapes.
    const double f = (imported.internal_frequencies_hz - native.internal_frequencies_hz).cwiseAbs().maxCoeff() /
                     native.internal_frequencies_hz.minCoeff();
    const double m_static = Relative(imported.M.topLeftCorner(12, 12), native.M.topLeftCorner(12, 12));
    const double shapes =
        Relative(imported.visualization->shapes.leftCols(12), native.visualization->shapes.leftCols(12));
    std::printf("[ info ] %s: frequencies %.2e, K_r %.2e, M_r static block %.2e, static shapes %.2e, mass %.2e\n",
                format.c_str(), f, Relative(imported.K, native.K), m_static, shapes,
                std::abs(imported.mass_properties.mass / native.mass_properties.mass - 1));
    EXPECT_LT(f, 1e-8) << format;
    EXPECT_LT(Relative(imported.K, native.K), 1e-8) << format;
    EXPECT_LT(m_static, 1e-8) << format;
    EXPECT_NEAR(imported.mass_properties.mass, native.mass_properties.mass, 1e-10 * native.mass_properties.mass);
    EXPECT_EQ(imported.provenance.element_type, "imported " + (format == "abaqus_coordinate" ? "abaqus" : format));
    ASSERT_TRUE(imported.visualization.has_value());
    EXPECT_EQ(imported.visualization->cell_type, CellType::kTet10);
    EXPECT_LT(shapes, 1e-8) << format;
    EXPECT_FALSE(imported.stress.has_value());
    // The same matrices in another form: the same superelement as the CalculiX files give (what
    // is unique of it, as above).
    if (!first) first = imported;
    EXPECT_LT(Relative(imported.K, first->K), 1e-12) << format;
    EXPECT_LT(Relative(imported.M.topLeftCorner(12, 12), first->M.topLeftCorner(12, 12)), 1e-12) << format;
    EXPECT_LT((imported.internal_frequencies_hz - first->internal_frequencies_hz).cwiseAbs().maxCoeff(),
              1e-12 * first->internal_frequencies_hz.maxCoeff())
        << format;
  }
  fs::remove_all(dir);
}

// An Abaqus/CAE deck with two instances of the exported bar, the second moved 2 m along y, and
// its coordinate-form matrices numbering both (the second's rows after the first's): the part of
// instance bar-2 is the native bar where that instance puts it (the same reduced K and
// frequencies, its interface at the moved root), and the deck's instances are named where one is
// missing or unknown. (A turned instance's matrices are in turned axes; the deck test checks the
// turn.)
TEST(ImportedModel, AnAbaqusDeckWithInstancesGivesTheNamedOne) {
  const fs::path dir = TempDir("instances");
  WriteText(dir / "bar.yaml", kBar);
  ExportPartMatrices(ReadPartFile((dir / "bar.yaml").string()), MatrixFormat::kAbaqusCoordinate, dir.string());
  const Superelement native = ReduceFile(dir / "bar.yaml");
  std::string deck = ReadText(dir / "bar.inp");
  deck = test::Replace(deck, "*End Assembly",
                       "*Instance, name=bar-2, part=bar\n0, 2, 0\n"
                       "*End Instance\n*End Assembly");
  WriteText(dir / "bar.inp", deck);
  long n = 0;
  for (const char* name : {"bar_STIF1.mtx", "bar_MASS1.mtx"}) {
    std::istringstream in(ReadText(dir / name));
    std::string both;
    std::vector<std::tuple<long, long, std::string>> rows;
    for (std::string line; std::getline(in, line);) {
      std::istringstream f(line);
      long i = 0, j = 0;
      std::string v;
      f >> i >> j >> v;
      rows.emplace_back(i, j, v);
      n = std::max(n, j);
    }
    for (int copy = 0; copy < 2; ++copy)
      for (const auto& [i, j, v] : rows)
        both += std::to_string(i + copy * n) + " " + std::to_string(j + copy * n) + "  " + v + "\n";
    WriteText(dir / name, both);
  }
  const std::string part =
      "name: bar\ntype: imported\ngeometry: {file: bar.inp}\n"
      "matrices: {format: abaqus, stiffness: bar_STIF1.mtx, mass: bar_MASS1.mtx, instance: INSTANCE}\n"
      "interfaces: [{name: root, group: xmin}, {name: tip, group: xmax, coupling: rbe3}]\n"
      "reduction: {internal_modes: 6}\n";
  WriteText(dir / "imported.yaml", test::Replace(part, "INSTANCE", "bar-2"));
  const Superelement imported = ReduceFile(dir / "imported.yaml");
  const double f = (imported.internal_frequencies_hz - native.internal_frequencies_hz).cwiseAbs().maxCoeff() /
                   native.internal_frequencies_hz.minCoeff();
  std::printf("[ info ] instance bar-2: frequencies %.2e, K_r %.2e, root at (%g, %g, %g)\n", f,
              Relative(imported.K, native.K), imported.interfaces[0].position.x(), imported.interfaces[0].position.y(),
              imported.interfaces[0].position.z());
  EXPECT_LT(f, 1e-8);
  EXPECT_LT(Relative(imported.K, native.K), 1e-8);
  // The root face's centre (0, 0.025, 0.025) moved to (0, 2.025, 0.025).
  EXPECT_LT((imported.interfaces[0].position - Eigen::Vector3d(0.0, 2.025, 0.025)).norm(), 1e-12);
  auto expect = [&](const std::string& yaml, const std::string& part_of_message) {
    WriteText(dir / "bad.yaml", yaml);
    const std::string m = test::ThrownMessage([&] { ReduceFile(dir / "bad.yaml"); });
    EXPECT_NE(m.find(part_of_message), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  };
  expect(test::Replace(part, ", instance: INSTANCE", ""),
         "has 2 instances (bar-1, bar-2): name one with matrices.instance");
  expect(test::Replace(part, "INSTANCE", "bar-3"), "has no instance 'bar-3' (it has bar-1, bar-2)");
  fs::remove_all(dir);
}

// The exported bar's matrices rewritten by the test in Nastran's DMIG (free field, the lower
// triangle as PARAM,EXTOUT,DMIGPCH punches it) and in Ansys' HBMAT form (Harwell-Boeing RSA with
// its mapping file) reduce to the superelement of the CalculiX files: K_r and M_r to 1e-12.
TEST(ImportedModel, NastranAndAnsysFormsReduceToTheSameSuperelement) {
  const fs::path dir = TempDir("nastran_ansys");
  WriteText(dir / "bar.yaml", kBar);
  ExportPartMatrices(ReadPartFile((dir / "bar.yaml").string()), MatrixFormat::kCalculix, dir.string());
  MatricesSpec spec;
  spec.format = MatrixFormat::kCalculix;
  spec.stiffness = (dir / "bar.sti").string();
  spec.mass = (dir / "bar.mas").string();
  spec.dofs = (dir / "bar.dof").string();
  const ImportedMatrices im = ReadImportedMatrices(spec);
  const long n = long(im.node.size());
  const char* labels[6] = {"UX", "UY", "UZ", "ROTX", "ROTY", "ROTZ"};
  {
    std::ofstream pch(dir / "bar.pch"), map(dir / "bar.mapping");
    pch.precision(17);
    map << " Matrix Eqn   Node   DOF\n";
    for (long r = 0; r < n; ++r)
      map << r + 1 << " " << im.node[size_t(r)] << " " << labels[im.component[size_t(r)]] << "\n";
    for (const auto& [name, A] : {std::pair{"KAAX", &im.K}, std::pair{"MAAX", &im.M}}) {
      pch << "DMIG," << name << ",0,6,2,0\n";
      for (int j = 0; j < A->outerSize(); ++j) {
        pch << "DMIG," << name << "," << im.node[size_t(j)] << "," << im.component[size_t(j)] + 1 << ",";
        for (SparseMatrix::InnerIterator it(*A, j); it; ++it)
          if (it.row() >= j)
            pch << ",\n+," << im.node[size_t(it.row())] << "," << im.component[size_t(it.row())] + 1 << ","
                << it.value();
        pch << "\n";
      }
    }
    for (const auto& [name, A] : {std::pair{"K.matrix", &im.K}, std::pair{"M.matrix", &im.M}}) {
      std::vector<long> pointer{1}, index;
      std::vector<double> value;
      for (int j = 0; j < A->outerSize(); ++j) {
        for (SparseMatrix::InnerIterator it(*A, j); it; ++it)
          if (it.row() >= j) {
            index.push_back(it.row() + 1);
            value.push_back(it.value());
          }
        pointer.push_back(long(index.size()) + 1);
      }
      std::ofstream hb(dir / name);
      char b[512];
      std::snprintf(b, sizeof b,
                    "%-72s%-8s\n%14d%14d%14d%14d%14d\nRSA           %14ld%14ld%14zu%14d\n%-16s%-16s%-20s\n", "bar",
                    "KEY", 0, 0, 0, 0, 0, n, n, index.size(), 0, "(8I10)", "(8I10)", "(1P,3E26.16)");
      hb << b;
      for (const std::vector<long>* block : {&pointer, &index})
        for (size_t k = 0; k < block->size(); ++k) {
          std::snprintf(b, sizeof b, "%10ld", (*block)[k]);
          hb << b << (k % 8 == 7 || k + 1 == block->size() ? "\n" : "");
        }
      for (size_t k = 0; k < value.size(); ++k) {
        std::snprintf(b, sizeof b, "%26.16E", value[k]);
        hb << b << (k % 3 == 2 || k + 1 == value.size() ? "\n" : "");
      }
    }
  }
  const std::string rest =
      "\ninterfaces: [{name: root, group: xmin}, {name: tip, group: xmax, coupling: rbe3}]\n"
      "reduction: {internal_modes: 6}\n";
  WriteText(dir / "ccx.yaml",
            "name: bar\ntype: imported\ngeometry: {file: bar.inp}\n"
            "matrices: {format: calculix, stiffness: bar.sti, mass: bar.mas, dofs: bar.dof}" +
                rest);
  WriteText(dir / "nastran.yaml",
            "name: bar\ntype: imported\ngeometry: {file: bar.inp}\n"
            "matrices: {format: nastran, stiffness: bar.pch, mass: bar.pch}" +
                rest);
  WriteText(dir / "ansys.yaml",
            "name: bar\ntype: imported\ngeometry: {file: bar.inp}\n"
            "matrices: {format: ansys, stiffness: K.matrix, mass: M.matrix, dofs: bar.mapping}" +
                rest);
  const Superelement reference = ReduceFile(dir / "ccx.yaml");
  for (const char* format : {"nastran", "ansys"}) {
    const Superelement other = ReduceFile(dir / (std::string(format) + ".yaml"));
    std::printf("[ info ] %s: K_r %.2e, M_r static block %.2e\n", format, Relative(other.K, reference.K),
                Relative(other.M.topLeftCorner(12, 12), reference.M.topLeftCorner(12, 12)));
    EXPECT_LT(Relative(other.K, reference.K), 1e-12) << format;
    EXPECT_LT(Relative(other.M.topLeftCorner(12, 12), reference.M.topLeftCorner(12, 12)), 1e-12) << format;
    EXPECT_EQ(other.provenance.element_type, std::string("imported ") + format);
  }
  fs::remove_all(dir);
}

// A beam: 6 DOFs per node (rotations), line cells, interfaces = named points of the part.
TEST(ImportedModel, BeamWithRotationalDofsRoundTrips) {
  const fs::path dir = TempDir("beam");
  const std::string beam =
      test::StraightBeamYaml(0.3, 12, "{shape: circle, diameter: 0.006}", "{E: 2.1e11, nu: 0.3, rho: 7850}",
                             "[{name: A}, {name: B}]", "reduction: {internal_modes: 5, floating_frame: mean_axes}\n");
  WriteText(dir / "rod.yaml", beam);
  const PartSpec part = ReadPartFile((dir / "rod.yaml").string());
  ExportPartMatrices(part, MatrixFormat::kCalculix, dir.string());
  const Superelement native = ReduceFile(dir / "rod.yaml");
  const std::string name = part.name;
  WriteText(dir / "imported.yaml",
            "name: rod\ntype: imported\ngeometry: {file: " + name +
                ".inp}\nmatrices: {format: calculix, "
                "stiffness: " +
                name + ".sti, mass: " + name + ".mas, dofs: " + name +
                ".dof}\n"
                "interfaces: [{name: A, group: A}, {name: B, select: {sphere: {center: [0.3, 0, 0], radius: 1e-3}, "
                "tolerance: 2e-3}}]\nreduction: {internal_modes: 5, floating_frame: mean_axes}\n");
  const Superelement imported = ReduceFile(dir / "imported.yaml");
  const double f = (imported.internal_frequencies_hz - native.internal_frequencies_hz).cwiseAbs().maxCoeff() /
                   native.internal_frequencies_hz.minCoeff();
  std::printf("[ info ] beam: frequencies %.2e, K_r %.2e, M_r %.2e (first %.3f Hz)\n", f,
              Relative(imported.K, native.K), Relative(imported.M, native.M), native.internal_frequencies_hz[0]);
  EXPECT_LT(f, 1e-8);
  EXPECT_LT(Relative(imported.K, native.K), 1e-8);
  EXPECT_LT(Relative(imported.M, native.M), 1e-8);
  // The inertia invariants on 6 DOFs per node (the rotations turn with the frame as the
  // translations do), to 1e-8 of each kind's largest.
  ASSERT_EQ(imported.inertia_gamma.size(), 3u);
  ASSERT_EQ(imported.inertia_xi.size(), 6u);
  for (const auto& [got, want] : {std::pair(&imported.inertia_gamma, &native.inertia_gamma),
                                  std::pair(&imported.inertia_xi, &native.inertia_xi)}) {
    double scale = 0.0, error = 0.0;
    for (size_t k = 0; k < want->size(); ++k) {
      scale = std::max(scale, (*want)[k].cwiseAbs().maxCoeff());
      error = std::max(error, ((*got)[k] - (*want)[k]).cwiseAbs().maxCoeff());
    }
    std::printf("[ info ] beam: inertia invariants %.2e\n", error / scale);
    EXPECT_LT(error, 1e-8 * scale);
  }
  EXPECT_EQ(imported.visualization->cell_type, CellType::kLine2);
  fs::remove_all(dir);
}

// CalculiX 2.20 assembles the same TET10 mesh (*FREQUENCY, SOLVER=MATRIXSTORAGE): its element
// integration differs from femb's in round-off and quadrature only, so the frequencies agree to
// 1e-4 (measured 6e-6 on a finer mesh).
TEST(ImportedModel, CalculixAssemblyMatchesFembsOwn) {
  if (std::system("command -v ccx > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "ccx not installed (apt-get install calculix-ccx)";
  const fs::path dir = TempDir("ccx");
  WriteText(dir / "bar.yaml", kBar);
  ExportPartMatrices(ReadPartFile((dir / "bar.yaml").string()), MatrixFormat::kCalculix, (dir / "mesh").string());
  WriteText(dir / "job.inp",
            "*INCLUDE, INPUT=mesh/bar.inp\n*MATERIAL, NAME=STEEL\n*ELASTIC\n2.1e11, 0.3\n*DENSITY\n7850.\n"
            "*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL\n*STEP\n*FREQUENCY, SOLVER=MATRIXSTORAGE\n*END STEP\n");
  ASSERT_EQ(std::system(("cd " + dir.string() + " && ccx job > ccx.log 2>&1").c_str()), 0) << ReadText(dir / "ccx.log");
  WriteText(dir / "native.yaml", test::Replace(kBar, "{shape: box, size: [1.0, 0.05, 0.05]}", "{file: mesh/bar.inp}"));
  WriteText(dir / "ccx.yaml",
            "name: bar\ntype: imported\ngeometry: {file: mesh/bar.inp}\n"
            "matrices: {format: calculix, stiffness: job.sti, mass: job.mas, dofs: job.dof}\n"
            "interfaces: [{name: root, group: xmin}, {name: tip, group: xmax, coupling: rbe3}]\n"
            "reduction: {internal_modes: 6}\n");
  const Superelement native = ReduceFile(dir / "native.yaml");
  const Superelement ccx = ReduceFile(dir / "ccx.yaml");
  const double f =
      ((ccx.internal_frequencies_hz.array() / native.internal_frequencies_hz.array()) - 1).abs().maxCoeff();
  std::printf("[ info ] CalculiX vs femb assembly: frequencies within %.2e, mass %.2e\n", f,
              ccx.mass_properties.mass / native.mass_properties.mass - 1);
  EXPECT_LT(f, 1e-4);
  EXPECT_NEAR(ccx.mass_properties.mass, native.mass_properties.mass, 1e-8 * native.mass_properties.mass);
  fs::remove_all(dir);
}

TEST(ImportedModel, BadMatricesAreOneLineEach) {
  const fs::path dir = TempDir("bad");
  WriteText(dir / "bar.yaml", kBar);
  ExportPartMatrices(ReadPartFile((dir / "bar.yaml").string()), MatrixFormat::kCalculix, dir.string());
  const std::string sti = ReadText(dir / "bar.sti"), dof = ReadText(dir / "bar.dof");
  const std::string first = sti.substr(0, sti.find('\n'));  // "1 1 value"
  const double k11 = std::stod(first.substr(4));
  auto reduce = [&](const std::string& sti_text, const std::string& dof_text, const std::string& extra = "") {
    WriteText(dir / "bad.sti", sti_text);
    WriteText(dir / "bad.dof", dof_text);
    WriteText(dir / "imported.yaml",
              "name: bar\ntype: imported\ngeometry: {file: bar.inp}\n"
              "matrices: {format: calculix, stiffness: bad.sti, mass: bar.mas, dofs: bad.dof}\n"
              "interfaces: [{name: root, group: xmin}]\n" +
                  extra);
    return test::ThrownMessage([&] { ReduceFile(dir / "imported.yaml"); });
  };
  auto expect = [](const std::string& message, const std::string& part) {
    EXPECT_NE(message.find(part), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  };
  char line[64];
  std::snprintf(line, sizeof line, "1 1 %.17g", -k11);
  expect(reduce(test::Replace(sti, first, line), dof), "bad.sti: the diagonal of node 1 u_x is negative");
  expect(reduce(sti + "2 1 5.0\n", dof), "and its transpose differ by");
  expect(reduce(sti + "2 1 nan\n", dof),
         "bad.sti:" + std::to_string(std::count(sti.begin(), sti.end(), '\n') + 1) + ": entry nan is not finite");
  expect(reduce(sti + "1 99999 1.0\n", dof), "outside the");
  expect(reduce(sti, test::Replace(dof, "1.1\n", "99999.1\n")), "node 99999 of the matrices is not in");
  expect(reduce(sti, test::Replace(dof, "1.2\n", "1.1\n")), "node 1 u_x appears twice");
  // A grounded spring on one DOF: the body no longer floats.
  std::snprintf(line, sizeof line, "1 1 %.17g", 2 * k11);
  expect(reduce(test::Replace(sti, first, line), dof), "the stiffness resists a rigid-body motion");
  // Keys the imported matrices cannot honour (stresses: not without the part's material).
  expect(reduce(sti, dof, "reduction: {stresses: true}\n"), "stresses of imported matrices need the part's material");
  expect(reduce(sti, dof, "reduction: {modal_derivatives: true}\n"), "modal derivatives need femb's own elements");
  WriteText(dir / "missing.yaml",
            "name: bar\ntype: imported\ngeometry: {file: bar.inp}\n"
            "matrices: {format: calculix, stiffness: nothere.sti, mass: bar.mas, dofs: bar.dof}\n"
            "interfaces: [{name: root, group: xmin}]\n");
  expect(test::ThrownMessage([&] { ReadPartFile((dir / "missing.yaml").string()); }), "nothere.sti' not found");
  fs::remove_all(dir);
}

// Thesis 8.2 with shapes from "another code": the free-free modes and static constraint modes of
// the exported rod, computed here densely on the imported matrices and written as a Matrix
// Market array, span the same space as femb's free_interface reduction of the native rod: the
// same internal frequencies. Four free-free modes alone do not move every interface direction.
TEST(ImportedModel, GeneralBasisFromAFileMatchesFreeInterface) {
  const fs::path dir = TempDir("general");
  const std::string rod = test::StraightBeamYaml(
      0.3, 10, "{shape: circle, diameter: 0.006}", "{E: 2.1e11, nu: 0.3, rho: 7850}", "[{name: A}, {name: B}]",
      "reduction: {method: free_interface, internal_modes: 8, floating_frame: mean_axes}\n");
  WriteText(dir / "rod.yaml", rod);
  const PartSpec part = ReadPartFile((dir / "rod.yaml").string());
  ExportPartMatrices(part, MatrixFormat::kCalculix, dir.string());
  const std::string name = part.name;
  MatricesSpec spec;
  spec.format = MatrixFormat::kCalculix;
  spec.stiffness = (dir / (name + ".sti")).string();
  spec.mass = (dir / (name + ".mas")).string();
  spec.dofs = (dir / (name + ".dof")).string();
  const ImportedMatrices im = ReadImportedMatrices(spec);
  const Eigen::MatrixXd K(im.K), M(im.M);
  const long n = K.rows();
  // Free-free modes (dense, shifted) and the static modes of the interface nodes 1 and 2 (A, B).
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(K + 1.0 * M, M);
  std::vector<long> boundary, interior;
  for (long r = 0; r < n; ++r) (im.node[size_t(r)] <= 2 ? boundary : interior).push_back(r);
  ASSERT_EQ(boundary.size(), 12u);
  Eigen::MatrixXd Kii(interior.size(), interior.size()), Kib(interior.size(), 12);
  for (size_t i = 0; i < interior.size(); ++i) {
    for (size_t j = 0; j < interior.size(); ++j) Kii(long(i), long(j)) = K(interior[i], interior[j]);
    for (size_t j = 0; j < 12; ++j) Kib(long(i), long(j)) = K(interior[i], boundary[j]);
  }
  const Eigen::MatrixXd Psi_i = -Kii.ldlt().solve(Kib);
  Eigen::MatrixXd V = Eigen::MatrixXd::Zero(n, 20);
  for (size_t j = 0; j < 12; ++j) {
    V(boundary[j], long(j)) = 1.0;
    for (size_t i = 0; i < interior.size(); ++i) V(interior[i], long(j)) = Psi_i(long(i), long(j));
  }
  V.rightCols(8) = eig.eigenvectors().middleCols(6, 8);
  auto write_array = [&](const fs::path& path, const Eigen::MatrixXd& A) {
    std::ofstream out(path);
    out.precision(17);
    out << "%%MatrixMarket matrix array real general\n% shapes\n" << A.rows() << " " << A.cols() << "\n";
    for (long j = 0; j < A.cols(); ++j)
      for (long i = 0; i < A.rows(); ++i) out << A(i, j) << "\n";
  };
  write_array(dir / "shapes.mtx", V);
  const std::string imported = "name: rod\ntype: imported\ngeometry: {file: " + name +
                               ".inp}\nmatrices: {format: calculix, "
                               "stiffness: " +
                               name + ".sti, mass: " + name + ".mas, dofs: " + name +
                               ".dof}\n"
                               "interfaces: [{name: A, group: A}, {name: B, group: B}]\n";
  WriteText(dir / "general.yaml",
            imported + "reduction: {method: general, basis: {file: shapes.mtx}, floating_frame: mean_axes}\n");
  const Superelement native = ReduceFile(dir / "rod.yaml");
  const Superelement general = ReduceFile(dir / "general.yaml");
  ASSERT_EQ(general.internal_frequencies_hz.size(), 8);
  const double f =
      ((general.internal_frequencies_hz.array() / native.internal_frequencies_hz.array()) - 1).abs().maxCoeff();
  std::printf(
      "[ info ] general basis from a file vs free_interface: internal frequencies within %.2e, K_r static block %.2e\n",
      f, Relative(general.K.topLeftCorner(12, 12), native.K.topLeftCorner(12, 12)));
  EXPECT_LT(f, 1e-8);
  EXPECT_LT(Relative(general.K.topLeftCorner(12, 12), native.K.topLeftCorner(12, 12)), 1e-8);
  EXPECT_EQ(general.provenance.reduction_method, "general");
  // Case 4: four free-free modes (with the rigid fields) cannot stretch or twist the rod: the file
  // holds those two directions by its interface constraint, and passes every check.
  write_array(dir / "few.mtx", eig.eigenvectors().middleCols(6, 4));
  WriteText(dir / "few.yaml",
            imported + "reduction: {method: general, basis: {file: few.mtx}, floating_frame: mean_axes}\n");
  const Superelement few = ReduceFile(dir / "few.yaml");
  EXPECT_EQ(few.interface_constraint.rows(), 2);
  EXPECT_EQ(few.interface_constraint.cols(), 12);
  EXPECT_EQ(few.n_internal_modes(), 0);
  const SuperelementChecks few_checks = CheckSuperelement(few);
  EXPECT_EQ(few_checks.first_failure(), nullptr)
      << (few_checks.first_failure() ? few_checks.first_failure()->detail : "");
  // A shapes file with the wrong number of rows.
  write_array(dir / "short.mtx", V.topRows(n - 1));
  WriteText(dir / "short.yaml",
            imported + "reduction: {method: general, basis: {file: short.mtx}, floating_frame: mean_axes}\n");
  EXPECT_NE(test::ThrownMessage([&] { ReduceFile(dir / "short.yaml"); }).find("short.mtx:3: the shapes have"),
            std::string::npos);
  // A size line announcing absurdly many shapes is refused before anything is allocated.
  WriteText(dir / "huge.mtx",
            "%%MatrixMarket matrix array real general\n" + std::to_string(n) + " 1000000000000\n1.0\n");
  WriteText(dir / "huge.yaml",
            imported + "reduction: {method: general, basis: {file: huge.mtx}, floating_frame: mean_axes}\n");
  EXPECT_NE(test::ThrownMessage([&] {
              ReduceFile(dir / "huge.yaml");
            }).find("huge.mtx:2: the file announces 1000000000000 shapes"),
            std::string::npos);
  WriteText(dir / "huge.mtx", "%%MatrixMarket matrix array real general\n" + std::to_string(n) + " 20\n1.0\n");
  EXPECT_NE(test::ThrownMessage([&] { ReduceFile(dir / "huge.yaml"); }).find("the file is too short"),
            std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace femb
