// solver/scene/scene_builder: from a scene's text to the system model. Two rods (a superelement
// file on disk) and a rigid block in a chain a-b-c-d:
//   - the model is solved about the mean of the bodies' placements; node positions are relative
//     to it and are the file's interface points moved by each body's placement;
//   - a node name shared by two bodies is one node (a rigid connection);
//   - joints along the tree become tree joints; one that closes a loop (here: a rigid body held
//     at two points) a cut joint with its redundant equations dropped and a note;
//   - loads land on their nodes; initial joint rates on their coordinates;
//   - each inconsistency is one line naming the file, the line and the entity.
#include "solver/scene/scene_builder.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>

#include "formats/input_error.h"
#include "formats/superelement_file.h"
#include "test_util.h"

namespace femb {
namespace {

namespace fs = std::filesystem;

class SceneBuilder : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string((fs::temp_directory_path() / ("femb_scene_builder_" + std::to_string(::getpid()))).string());
    fs::create_directories(*dir_);
    WriteSuperelementFile(
        test::Reduce(test::StraightBeamYaml(0.5, 4, "{shape: circle, diameter: 0.02}", "{E: 2.0e9, nu: 0.3, rho: 7800}",
                                            "[{name: A}, {name: B}]", "reduction: {internal_modes: 2}\n")),
        *dir_ + "/rod.h5");
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
  }
  // rod0 from (10, 0, 0) along x, rod1 from its end turned by 90 degrees about z (along y), a
  // rigid block at rod1's far end; `joints`, `loads` and `extra` appended.
  static std::string Text(const std::string& joints, const std::string& loads = "", const std::string& extra = "") {
    return "name: chain\nunits: SI\nbodies:\n"
           "  - {name: rod0, superelement: " +
           *dir_ +
           "/rod.h5, placement: {position: [10, 0, 0]}, nodes: {A: a, B: b}}\n"
           "  - {name: rod1, superelement: " +
           *dir_ +
           "/rod.h5, placement: {position: [10.5, 0, 0], rotation: [0, 0, 1.5707963267948966]},"
           " nodes: {A: b, B: c}}\n"
           "  - {name: block, type: rigid, mass: 1.0, inertia: [1e-3, 1e-3, 1e-3], center_of_mass: [0, 0, 0],\n"
           "     points: {P: [0, 0, 0], Q: [-0.5, 0, 0]}, placement: {position: [10.5, 0.5, 0]},"
           " nodes: {P: c, Q: d}}\n"
           "joints:\n" +
           joints + loads + "analysis: {type: static, end_time: 1, steps: 1}\n" + extra;
  }
  static Scene Build(const std::string& text) { return BuildScene(ParseScene(text, "chain.yaml")); }
  // The message of the InputError building `text` throws ("" when none).
  static std::string ErrorOf(const std::string& text) {
    try {
      Build(text);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }
  static std::string* dir_;
};
std::string* SceneBuilder::dir_ = nullptr;

TEST_F(SceneBuilder, NodesAreThePlacedInterfacesAboutTheScenesOrigin) {
  const Scene scene =
      Build(Text("  - {type: clamp, node: a}\n", "loads:\n  - {type: force, node: c, force: [0, 0, -5]}\n"));
  const SystemModel& model = scene.model;
  // The mean of the three placements.
  const Eigen::Vector3d origin =
      (Eigen::Vector3d(10, 0, 0) + Eigen::Vector3d(10.5, 0, 0) + Eigen::Vector3d(10.5, 0.5, 0)) / 3;
  EXPECT_LT((scene.origin - origin).norm(), 1e-15);
  const auto at = [&](const std::string& node) {
    return Eigen::Vector3d(model.node_x0[size_t(scene.node_index.at(node))] + scene.origin);
  };
  EXPECT_LT((at("a") - Eigen::Vector3d(10, 0, 0)).norm(), 1e-14);
  EXPECT_LT((at("b") - Eigen::Vector3d(10.5, 0, 0)).norm(), 1e-14);
  EXPECT_LT((at("c") - Eigen::Vector3d(10.5, 0.5, 0)).norm(), 1e-14);
  EXPECT_LT((at("d") - Eigen::Vector3d(10.0, 0.5, 0)).norm(), 1e-14);
  // Shared names are one node: b is rod0's B and rod1's A, c rod1's B and the block's P.
  EXPECT_EQ(model.body_nodes[0][1], model.body_nodes[1][0]);
  EXPECT_EQ(model.body_nodes[1][1], scene.node_index.at("c"));
  EXPECT_EQ(model.bodies.size(), 3u);
  EXPECT_EQ(scene.body_names, (std::vector<std::string>{"rod0", "rod1", "block"}));
  // rod1's nodes turned with it: its interface frames' x axis along global y.
  EXPECT_LT((model.node_R0[size_t(scene.node_index.at("c"))].col(0) - Eigen::Vector3d::UnitY()).norm(), 1e-14);
  // The clamp is a rigid joint to the ground; the load sits on c.
  EXPECT_TRUE(FixedToGround(model, scene.node_index.at("a")));
  ASSERT_EQ(model.loads.size(), 1u);
  EXPECT_EQ(model.loads[0].node, scene.node_index.at("c"));
  EXPECT_EQ(model.loads[0].force, Eigen::Vector3d(0, 0, -5));
  EXPECT_TRUE(model.cut_joints.empty());
}

TEST_F(SceneBuilder, TheJointThatClosesTheLoopIsCut) {
  // The block on revolutes about z at d and at c: the joint at d roots the block's tree there, so
  // c already hangs on d (a rigid offset) and its revolute closes a loop. Of the cut joint's 5
  // equations only 1 moves with the tree's one coordinate (d's angle): 4 are dropped.
  const Scene scene =
      Build(Text("  - {type: revolute, node: d, axis: [0, 0, 1]}\n"
                 "  - {type: revolute, node: c, axis: [0, 0, 1]}\n",
                 "", "initial_velocity: {d: {joint: [1.5]}}\n"));
  const SystemModel& model = scene.model;
  ASSERT_EQ(model.cut_joints.size(), 1u);
  EXPECT_EQ(model.cut_joints[0].joint.child, scene.node_index.at("c"));
  EXPECT_EQ(model.cut_joints[0].name.rfind("chain.yaml:", 0), 0u) << model.cut_joints[0].name;
  EXPECT_EQ(model.cut_joints[0].equations.size(), 1u);
  bool noted = false;
  for (const std::string& note : scene.notes) noted |= note.find("closes a loop") != std::string::npos;
  EXPECT_TRUE(noted);
  // The initial rate sits on d's revolute coordinate.
  const DofMap& dofs = model.dofs();
  EXPECT_EQ(scene.initial_velocity[dofs.node_first(scene.node_index.at("d"))], 1.5);
  EXPECT_EQ(scene.initial_velocity.norm(), 1.5);
  EXPECT_LT(LoopViolation(model, InitialState(model)), 1e-15);
  // cut: true cuts a joint that could be a tree joint: the block then floats, held at d by all 5
  // equations.
  const Scene cut = Build(Text("  - {type: revolute, node: d, axis: [0, 0, 1], cut: true}\n"));
  ASSERT_EQ(cut.model.cut_joints.size(), 1u);
  EXPECT_EQ(cut.model.cut_joints[0].equations.size(), 5u);
}

TEST_F(SceneBuilder, EachInconsistencyIsOneLineNamingWhere) {
  const auto expect = [](const std::string& message, const std::string& what) {
    EXPECT_EQ(message.rfind("chain.yaml", 0), 0u) << "expected: " << what;
    EXPECT_NE(message.find(what), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  };
  const std::string clamp = "  - {type: clamp, node: a}\n";
  // A node two bodies put in different places, and a rigid body's point away from its node.
  std::string text = Text(clamp);
  text.replace(text.find("nodes: {A: b, B: c}"), 19, "nodes: {A: c, B: b}");
  expect(ErrorOf(text), "node 'b' is placed at (10.5, 0.5, 0) by body 'rod1' but at (10.5, 0, 0) by body 'rod0'");
  text = Text(clamp);
  text.replace(text.find("nodes: {P: c, Q: d}"), 19, "nodes: {P: d, Q: c}");
  expect(ErrorOf(text), "rigid body 'block': point 'Q' at a different place than node 'c' of body 'rod1'");
  // An interface the file does not have, and one left unmapped.
  text = Text(clamp);
  text.replace(text.find("nodes: {A: a, B: b}"), 19, "nodes: {A: a, C: b}");
  expect(ErrorOf(text), "has no interface 'C' (it has: A, B)");
  text = Text(clamp);
  text.replace(text.find("nodes: {A: a, B: b}"), 19, "nodes: {A: a}");
  expect(ErrorOf(text), "interface 'B' is not mapped to a scene node under 'nodes'");
  // A load on a clamped node.
  expect(ErrorOf(Text(clamp, "loads:\n  - {type: force, node: a, force: [1, 0, 0]}\n")),
         "load on node 'a', which is clamped to the ground");
  // A revolute between nodes apart.
  expect(ErrorOf(Text(clamp + "  - {type: revolute, node: d, parent: a, axis: [0, 0, 1]}\n")),
         "revolute joint between nodes 'd' and 'a': the nodes are 0.5 apart at t = 0");
  // The block driven at d and at c (the second drive closes the loop), and driven at d with c on a
  // revolute: the loop has no coordinate free to follow the drive (dropping its equations, as a
  // loop the tree closes rigidly has them, would let c leave its pin without a word).
  expect(ErrorOf(Text("  - {type: revolute, node: d, axis: [0, 0, 1], prescribed: f}\n"
                      "  - {type: revolute, node: c, axis: [0, 0, 1], prescribed: f}\n",
                      "", "functions:\n  f: {type: linear, slope: 1}\n")),
         "revolute joint of node 'c' is prescribed but closes a loop");
  expect(ErrorOf(Text("  - {type: revolute, node: d, axis: [0, 0, 1], prescribed: f}\n"
                      "  - {type: revolute, node: c, axis: [0, 0, 1]}\n",
                      "", "functions:\n  f: {type: linear, slope: 1}\n")),
         "revolute joint of node 'c' to the ground: the loop it closes locks the drive of node 'd' (its translation");
}

}  // namespace
}  // namespace femb
