// Abaqus decks (formats/abaqus_deck.h) written by hand to the Abaqus keywords' documentation:
// parts placed by instances (translation, then rotation about an axis through two points),
// sets by label, GENERATE, INSTANCE= and "instance.set" references, element data over
// continuation lines, and the equation numbering of the coordinate matrix output derived from the
// element types at each node; bad decks stop with one line naming the file and line.
#include "formats/abaqus_deck.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "test_util.h"

namespace femb {
namespace {

namespace fs = std::filesystem;

// A tetrahedron with a shell on one face (nodes 2, 3, 10 carry rotations; node lines with a
// trailing comma and with a normal), placed twice, and a frame part of one S4R shell and one B31
// beam; a reference point at the assembly level.
constexpr const char* kDeck = R"(*Heading
 two blocks and a frame
** a comment line
*Part, name=Block
*Node
     10,  0.,  0.,  0.
      2,  1.,  0.,  0.,
      3,  0.,  1.,  0., 0., 0., 1.
      4,  0.,  0.,  1.
*Element, type=C3D4, elset=Solid
1, 10, 2, 3, 4
*Element, type=S3
2, 10, 2, 3
*Nset, nset=Base
 10, 2, 3
*Elset, elset=All, generate
 1, 2, 1
*End Part
*Part, name=Frame
*Node
1, 0., 0., 0.
2, 1., 0., 0.
3, 1., 1., 0.
4, 0., 1., 0.
5, 0., 0., 1.
*Element, type=S4R
1, 1, 2, 3, 4
*Element, type=B31
2, 1, 5
*End Part
*Assembly, name=Assembly
*Instance, name=Block-1, part=Block
*End Instance
*Instance, name=Block-2, part=BLOCK
 5., 0., 0.
 5., 0., 0., 5., 0., 1., 90.
*End Instance
*Instance, name=Frame-1, part=Frame
*End Instance
*Nset, nset=Tip, instance=Block-2
 4,
*Nset, nset=Corners
 Block-1.4, Block-2.Base
*Node
 1, 0., 0., 0.
*End Assembly
*Step
*Static
*End Step
)";

std::string WriteDeck(const std::string& name, const std::string& text) {
  const fs::path path = fs::temp_directory_path() / ("femb_deck_" + name + "_" + std::to_string(::getpid()) + ".inp");
  std::ofstream(path) << text;
  return path.string();
}

TEST(AbaqusDeck, InstancesPlaceTheirPartsAndKeepTheirSets) {
  const std::string path = WriteDeck("assembly", kDeck);
  const AbaqusDeck deck = ReadAbaqusDeck(path);
  EXPECT_TRUE(deck.assembly);
  EXPECT_EQ(deck.assembly_nodes, 1);
  ASSERT_EQ(deck.instances.size(), 3u);
  EXPECT_EQ(deck.instances[1].name, "Block-2");
  const AbaqusMesh& b1 = deck.instances[0];
  const AbaqusMesh& b2 = deck.instances[1];
  EXPECT_EQ(b1.labels, (std::vector<long>{2, 3, 4, 10}));
  // Block-2: moved by (5, 0, 0), then turned 90 deg about z through (5, 0, 0): part node 2 at
  // (1, 0, 0) goes to (6, 0, 0), then to (5, 1, 0); node 3 at (0, 1, 0) to (4, 0, 0).
  EXPECT_LT((b2.nodes.row(0) - Eigen::RowVector3d(5, 1, 0)).norm(), 1e-15);
  EXPECT_LT((b2.nodes.row(1) - Eigen::RowVector3d(4, 0, 0)).norm(), 1e-15);
  EXPECT_LT((b2.nodes.row(3) - Eigen::RowVector3d(5, 0, 0)).norm(), 1e-15);
  EXPECT_TRUE(b1.nodes.row(0) == Eigen::RowVector3d(1, 0, 0));  // Block-1 stays where the part is
  // Sets keep their spelling; an element set gives its elements' nodes.
  EXPECT_EQ(b2.node_sets.at("Base"), (std::vector<int>{0, 1, 3}));
  EXPECT_EQ(b2.node_sets.at("Tip"), (std::vector<int>{2}));
  EXPECT_EQ(b2.node_sets.at("All"), (std::vector<int>{0, 1, 2, 3}));
  EXPECT_EQ(b2.node_sets.at("Corners"), (std::vector<int>{0, 1, 3}));
  EXPECT_EQ(b1.node_sets.at("Corners"), (std::vector<int>{2}));
  EXPECT_EQ(b1.node_sets.count("Tip"), 0u);
  EXPECT_EQ(PickInstance(deck, "frame-1", "part.yaml:3"), 2);
  fs::remove(path);
}

TEST(AbaqusDeck, CoordinateEquationsFollowNodesAndTheirElementsDofs) {
  const std::string path = WriteDeck("equations", kDeck);
  const std::vector<AbaqusEquation> eq = CoordinateEquations(ReadAbaqusDeck(path));
  // Each block: nodes 2, 3, 10 with six (solid and shell), node 4 with three: 21. The frame:
  // five nodes with six (shell and beam): 30.
  ASSERT_EQ(eq.size(), 21u + 21u + 30u);
  auto at = [&](size_t k) { return std::tuple(eq[k].instance, eq[k].node, eq[k].component); };
  EXPECT_EQ(at(0), std::tuple(0, 2L, 0));
  EXPECT_EQ(at(5), std::tuple(0, 2L, 5));
  EXPECT_EQ(at(12), std::tuple(0, 4L, 0));
  EXPECT_EQ(at(15), std::tuple(0, 10L, 0));
  EXPECT_EQ(at(21), std::tuple(1, 2L, 0));
  EXPECT_EQ(at(42), std::tuple(2, 1L, 0));
  EXPECT_EQ(at(71), std::tuple(2, 5L, 5));
  fs::remove(path);
}

TEST(AbaqusDeck, ElementLinesContinue) {
  // A flat deck: C3D10 over two lines after a trailing comma, C3D20 over two lines without one
  // (its node count says it goes on).
  std::string text = "*NODE, NSET=NALL\n";
  for (int n = 1; n <= 30; ++n) text += std::to_string(n) + ", " + std::to_string(n) + ".0, 0, 0\n";
  text += "*ELEMENT, TYPE=C3D10, ELSET=E1\n1, 1, 2, 3, 4, 5, 6,\n 7, 8, 9, 10\n";
  text += "*ELEMENT, TYPE=C3D20R\n2, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 23, 24, 25\n";
  text += "26, 27, 28, 29, 30\n";
  const std::string path = WriteDeck("flat", text);
  const AbaqusDeck deck = ReadAbaqusDeck(path);
  EXPECT_FALSE(deck.assembly);
  ASSERT_EQ(deck.instances.size(), 1u);
  const AbaqusMesh& m = deck.instances[0];
  ASSERT_EQ(m.elements.size(), 2u);
  EXPECT_EQ(m.elements[0].nodes.size(), 10u);
  EXPECT_EQ(m.elements[0].nodes.back(), 10);
  EXPECT_EQ(m.elements[1].type, "C3D20R");
  EXPECT_EQ(m.elements[1].nodes.size(), 20u);
  EXPECT_EQ(m.node_sets.at("NALL").size(), 30u);
  EXPECT_EQ(m.node_sets.at("E1").size(), 10u);
  EXPECT_EQ(CoordinateEquations(deck).size(), 90u);
  EXPECT_EQ(PickInstance(deck, "", "part.yaml:3"), 0);
  fs::remove(path);
}

TEST(AbaqusDeck, BadDecksAreOneLineEach) {
  auto message = [](const std::string& name, const std::string& text) {
    const std::string path = WriteDeck(name, text);
    const std::string m = test::ThrownMessage([&] { CoordinateEquations(ReadAbaqusDeck(path)); });
    fs::remove(path);
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    return m;
  };
  auto has = [](const std::string& m, const std::string& part) { EXPECT_NE(m.find(part), std::string::npos) << m; };
  const std::string nodes = "*Node\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 0\n4, 0, 0, 1\n";
  has(message("include", nodes + "*Include, input=more.inp\n"), ".inp:6: *Include is not read");
  has(message("node", nodes + "*Element, type=C3D4\n1, 1, 2, 3, 99\n"), "element 1 uses node 99");
  has(message("type", "*Element\n"), ".inp:1: *Element without type=");
  has(message("number", "*Node\n1, 0, zero, 0\n"), ".inp:2: 'zero' is not a number");
  has(message("hybrid", nodes + "*Element, type=C3D4H\n1, 1, 2, 3, 4\n"), ".inp:6: element type C3D4H");
  has(message("part", "*Assembly, name=A\n*Instance, name=I, part=Nothing\n*End Instance\n*End Assembly\n"),
      "instance I places part NOTHING");
  has(message("instance_set",
              "*Assembly, name=A\n*Instance, name=I, part=Nothing\n*End Instance\n*Nset, nset=S\n I.SET\n"),
      ".inp:5: instance I places part NOTHING, which is not defined");
  has(message("set", nodes + "*Nset, nset=S\n1, Other\n"), "'Other' is neither a label nor a set");
  has(message("short", nodes + "*Element, type=C3D4\n1, 1, 2, 3, 4\n*Element, type=C3D10\n2, 1, 2, 3\n"),
      "the file ends inside an element's data line");
  const std::string path = WriteDeck("pick", kDeck);
  const AbaqusDeck deck = ReadAbaqusDeck(path);
  has(test::ThrownMessage([&] { PickInstance(deck, "", "part.yaml:3"); }),
      "part.yaml:3: " + path + " has 3 instances (Block-1, Block-2, Frame-1): name one with matrices.instance");
  has(test::ThrownMessage([&] { PickInstance(deck, "Block-3", "part.yaml:3"); }), "has no instance 'Block-3'");
  fs::remove(path);
}

}  // namespace
}  // namespace femb
