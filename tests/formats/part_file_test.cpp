// Part file parsing: every bad input gives one line naming the file, line and key.
#include "formats/part_file.h"

#include <gtest/gtest.h>

#include "test_util.h"

namespace femb {
namespace {

const std::string kGood =
    "name: rod\n"                                  // 1
    "type: beam\n"                                 // 2
    "material: {E: 2.0e11, nu: 0.3, rho: 7870}\n"  // 3
    "section: {shape: circle, diameter: 0.006}\n"  // 4
    "beam:\n"                                      // 5
    "  points:\n"                                  // 6
    "    A: [0, 0, 0]\n"                           // 7
    "    B: [0.3, 0, 0]\n"                         // 8
    "  segments:\n"                                // 9
    "    - {from: A, to: B, elements: 10}\n"       // 10
    "interfaces:\n"                                // 11
    "  - {name: A}\n"                              // 12
    "  - {name: B}\n"                              // 13
    "reduction:\n"                                 // 14
    "  internal_modes: 4\n";                       // 15

using test::Replace;

std::string Error(const std::string& text, const std::vector<std::string>& overrides = {}) {
  return test::ThrownMessage([&] { ParsePart(text, "part.yaml", overrides); });
}

TEST(PartFile, GoodFileParses) {
  const PartSpec p = ParsePart(kGood, "part.yaml");
  EXPECT_EQ(p.name, "rod");
  EXPECT_EQ(p.units.system, "SI");
  EXPECT_EQ(p.beam.points.size(), 2u);
  EXPECT_EQ(p.beam.segments[0].elements, 10);
  EXPECT_EQ(p.interfaces.size(), 2u);
  EXPECT_EQ(p.interfaces[1].point, 1);
  EXPECT_EQ(p.reduction.internal_modes, 4);
  EXPECT_EQ(p.reduction.floating_frame, FloatingFrameType::kCenterOfMass);
  EXPECT_FALSE(p.reduction.solver.has_value());  // cholmod on one process, petsc on several
  const PartSpec mpi = ParsePart(kGood, "part.yaml", {"reduction.solver=petsc"});
  EXPECT_EQ(mpi.reduction.solver, ReductionSolver::kPetsc);
  EXPECT_EQ(mpi.reduction.where_solver, "--set reduction.solver");
}

TEST(PartFile, SetOverridesKeys) {
  const PartSpec p = ParsePart(
      kGood, "part.yaml",
      {"reduction.internal_modes=7", "reduction.floating_frame=mean_axes", "units=mm-t-s", "check_units=false"});
  EXPECT_EQ(p.reduction.internal_modes, 7);
  EXPECT_EQ(p.reduction.floating_frame, FloatingFrameType::kMeanAxes);
  EXPECT_EQ(p.units.length, "mm");
  EXPECT_EQ(p.units.stress, "MPa");
  EXPECT_NE(ParsePart(kGood, "part.yaml").text_hash, p.text_hash);
}

// A whole list item: replaced by index, or appended one past the last; an error inside it names
// the --set that put it there.
TEST(PartFile, SetReplacesOrAppendsAWholeListItem) {
  const PartSpec replaced = ParsePart(kGood, "part.yaml", {"interfaces[1]={name: C, point: B}"});
  ASSERT_EQ(replaced.interfaces.size(), 2u);
  EXPECT_EQ(replaced.interfaces[1].name, "C");
  EXPECT_EQ(replaced.interfaces[1].point, ParsePart(kGood, "part.yaml").interfaces[1].point);
  // A point in the middle: the segment replaced by two, a third interface appended.
  const PartSpec appended =
      ParsePart(kGood, "part.yaml",
                {"beam.points.M=[0.15, 0, 0]", "beam.segments[0]={from: A, to: M, elements: 5}",
                 "beam.segments[1]={from: M, to: B, elements: 5}", "interfaces[2]={name: C, point: M}"});
  ASSERT_EQ(appended.interfaces.size(), 3u);
  EXPECT_EQ(appended.interfaces[2].name, "C");
  EXPECT_EQ(appended.beam.segments.size(), 2u);
  const std::string beyond = Error(kGood, {"interfaces[5]={name: C}"});
  EXPECT_NE(
      beyond.find("--set interfaces[5]={name: C}: 'interfaces' has no item 5 in part.yaml (it has 2; [2] appends one)"),
      std::string::npos)
      << beyond;
  const std::string inside = Error(kGood, {"interfaces[1]={name: C, point: Q}"});
  EXPECT_NE(inside.find("--set interfaces[1].point: interface point 'Q' not found"), std::string::npos) << inside;
  const std::string not_list = Error(kGood, {"reduction[0]=3"});
  EXPECT_NE(not_list.find("'reduction' is not a list"), std::string::npos) << not_list;
}

TEST(PartFile, BadInputNamesFileLineAndKey) {
  struct Case {
    std::string text, expected;
  };
  const std::vector<Case> cases = {
      {Replace(kGood, "  internal_modes: 4\n", "  internal_modes: 4\n  inernal_modes: 5\n"),
       "part.yaml:16: reduction.inernal_modes: unknown key 'inernal_modes' in 'reduction'"},
      {Replace(kGood, "E: 2.0e11", "E: -5"), "part.yaml:3: material.E: must be positive, got -5"},
      {Replace(kGood, "E: 2.0e11", "E: 0"), "part.yaml:3: material.E: must be positive"},
      {Replace(kGood, "rho: 7870", "rho: 0"), "part.yaml:3: material.rho: must be positive"},
      {Replace(kGood, "nu: 0.3", "nu: 0.5"), "part.yaml:3: material.nu: Poisson's ratio must be in (-1, 0.5), got 0.5"},
      {Replace(kGood, "nu: 0.3", "nu: -1.2"), "material.nu: Poisson's ratio must be in (-1, 0.5)"},
      {Replace(kGood, "B: [0.3, 0, 0]", "B: [0, 0, 0]"), "part.yaml:10: beam.segments[0]: zero-length element"},
      {Replace(kGood, "  - {name: B}\n", "  - {name: B, point: C}\n"),
       "part.yaml:13: interfaces[1].point: interface point 'C' not found in beam.points"},
      {Replace(kGood, "interfaces:\n  - {name: A}\n  - {name: B}\n", ""), "part.yaml: no interface defined"},
      {Replace(kGood, "interfaces:\n  - {name: A}\n  - {name: B}\n", "interfaces: []\n"),
       "part.yaml: no interface defined"},
      {Replace(kGood, "name: rod\n", "name: rod\nbogus: 1\n"), "part.yaml:2: bogus: unknown key 'bogus'"},
      {Replace(kGood, "{from: A, to: B", "{from: A, to: X"),
       "part.yaml:10: beam.segments[0].to: point 'X' is not defined"},
      {Replace(kGood, "shape: circle", "shape: hexagon"),
       "part.yaml:4: section.shape: unknown section shape 'hexagon'"},
      {Replace(kGood, "type: beam", "type: shell"), "part.yaml:2: type: unknown part type 'shell'"},
      {Replace(kGood, "section: {shape: circle, diameter: 0.006}\n", ""),
       "part.yaml:1: missing required key 'section'"},
      {Replace(kGood, "elements: 10", "elements: 0"),
       "part.yaml:10: beam.segments[0].elements: a segment needs at least 1 element"},
      {Replace(kGood, "  internal_modes: 4\n", "  solver: mumps\n"),
       "part.yaml:15: reduction.solver: expected cholmod or petsc, got 'mumps'"},
      {Replace(kGood, "  internal_modes: 4\n", "  floating_frame: interface:Q\n"),
       "part.yaml:15: reduction.floating_frame: floating frame interface 'Q' is not one of the part's interfaces"},
  };
  for (const Case& c : cases) {
    const std::string message = Error(c.text);
    EXPECT_NE(message.find(c.expected), std::string::npos) << "expected: " << c.expected << "\n     got: " << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << "one line: " << message;
  }
}

TEST(PartFile, YamlSyntaxErrorNamesTheLine) {
  const std::string message = Error(Replace(kGood, "    B: [0.3, 0, 0]\n", "    B: [0.3, 0, 0\n"));
  EXPECT_NE(message.find("part.yaml:"), std::string::npos) << message;
  EXPECT_NE(message.find("YAML syntax error"), std::string::npos) << message;
}

TEST(PartFile, BadOverridesAreNamed) {
  EXPECT_NE(
      Error(kGood, {"reduction.internal_modes=-3"}).find("--set reduction.internal_modes: must be zero or positive"),
      std::string::npos)
      << Error(kGood, {"reduction.internal_modes=-3"});
  EXPECT_NE(Error(kGood, {"reduction.modes=3"}).find("--set reduction.modes: unknown key 'modes'"), std::string::npos)
      << Error(kGood, {"reduction.modes=3"});
  EXPECT_NE(Error(kGood, {"novalue"}).find("expected key.path=value"), std::string::npos);
  // Found by fuzzing (tests/fuzz/regressions/yaml_fuzz/set_key_below_list_item): a key below a
  // list item that is a number threw yaml-cpp's BadSubscript instead of an InputError.
  const std::string below = Error(kGood, {"beam.points.B[0].x.y=3"});
  EXPECT_NE(below.find("--set beam.points.B[0].x.y=3: 'beam.points.B[0]' is not a mapping"), std::string::npos)
      << below;
}

// Mixed units: a value plausible only in another unit system names that system; check_units:
// false lets a deliberate outlier through.
TEST(PartFile, MixedUnitsAreFlagged) {
  const std::string rho = Error(Replace(kGood, "rho: 7870", "rho: 7.87e-9"));
  EXPECT_NE(rho.find("part.yaml:3: material.rho: rho = 7.87e-09 is implausible for units SI (kg/m^3"),
            std::string::npos)
      << rho;
  EXPECT_NE(rho.find("it looks like mm-t-s or mm-kg-ms (mixed units?)"), std::string::npos) << rho;
  const std::string E = Error(Replace(kGood, "E: 2.0e11", "E: 2.0e5"));
  EXPECT_NE(E.find("material.E: E = 2e+05 is implausible for units SI (Pa"), std::string::npos) << E;
  EXPECT_NE(E.find("it looks like mm-t-s"), std::string::npos) << E;
  const std::string size = Error(Replace(kGood, "B: [0.3, 0, 0]", "B: [300, 0, 0]"));
  EXPECT_NE(size.find("beam.points: part size (bounding-box diagonal) = 300 is implausible for units SI (m"),
            std::string::npos)
      << size;
  const std::string mm = Error(kGood, {"units=mm-t-s"});
  EXPECT_NE(mm.find("rho = 7870 is implausible for units mm-t-s (t/mm^3, expected 5e-12 .. 3e-08); it looks like SI"),
            std::string::npos)
      << mm;
  EXPECT_NO_THROW(ParsePart(Replace(kGood, "rho: 7870", "rho: 7.87e-9"), "part.yaml", {"check_units=false"}));
}

TEST(PartFile, ChoicesListTheAllowedValues) {
  const std::string solid =
      "name: s\ntype: solid\ncheck_units: false\nmaterial: {E: 1, nu: 0.3, rho: 1}\ngeometry: {shape: box, size: [1, "
      "1, 1]}\n"
      "mesh: {elements: prisms}\ninterfaces: [{name: A, group: xmin}]\n";
  const std::string message = Error(solid);
  EXPECT_NE(message.find("part.yaml:6: mesh.elements: expected tetrahedra or hexahedra, got 'prisms'"),
            std::string::npos)
      << message;
}

TEST(PartFile, MissingFileIsNamed) {
  const std::string message = test::ThrownMessage([] { ReadPartFile("/nonexistent/part.yaml"); });
  EXPECT_NE(message.find("/nonexistent/part.yaml: cannot open part file"), std::string::npos) << message;
}

}  // namespace
}  // namespace femb
