// solver/output/results_recorder: what Record is given is what results.h5 and probes.csv hold.
// A rigid arm on a revolute support 1e3 m from the origin (the model is solved relative to the
// scene's origin; the files are in scene coordinates), turned by hand to known angles past 2 pi:
//   - every node's position, quaternion and velocities are the closed form of the turned arm;
//   - the probes' columns are the same numbers, in full precision in results.h5 and in
//     probes.csv; the joint probe is the angle itself (not wrapped to (-pi, pi]);
//   - energies, momentum and reactions are stored as given;
//   - a write during the run says so in `status`, and a recorder dropped without Finish leaves
//     neither probes.csv nor its temporary.
#include "solver/output/results_recorder.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "formats/scene_file.h"
#include "solver/rotation.h"

namespace femb {
namespace {

namespace fs = std::filesystem;

const Eigen::Vector3d kPivot(1000.0, -2.0, 0.5);

std::string SceneText() {
  return "name: arm\nunits: SI\nbodies:\n"
         "  - {name: arm, type: rigid, mass: 2.0, inertia: [0.01, 0.2, 0.2], center_of_mass: [0.5, 0, 0],\n"
         "     points: {P: [0, 0, 0], Q: [1, 0, 0]}, placement: {position: [1000.0, -2.0, 0.5]},\n"
         "     nodes: {P: pivot, Q: tip}}\n"
         "joints:\n  - {type: revolute, node: pivot, axis: [0, 0, 1]}\n"
         "analysis: {type: dynamic, end_time: 1, step: 0.1}\n"
         "outputs:\n  reactions: true\n  probes:\n"
         "    - {name: tip, node: tip, quantities: [position, velocity, rotation]}\n"
         "    - {name: hinge, node: pivot, quantities: [joint]}\n";
}

std::string TempDir(const std::string& name) {
  return (fs::temp_directory_path() / ("femb_recorder_test_" + std::to_string(::getpid()) + "_" + name)).string();
}

std::vector<std::vector<std::string>> ReadCsv(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::vector<std::string>> rows;
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> cells;
    std::stringstream s(line);
    for (std::string cell; std::getline(s, cell, ',');) cells.push_back(cell);
    rows.push_back(cells);
  }
  return rows;
}

struct Recorded {
  Scene scene = BuildScene(ParseScene(SceneText(), "arm.yaml"));
  std::vector<double> time, angle;
  double rate = 2.0;
  // Records n output steps at angles 0.9 i with rate 2 rad/s, energies i, 2 i, 3 i, momentum
  // (i, 0, 0), (0, 0, 2 i) about the model's origin and a reaction (i, ..) at the pivot.
  void Run(ResultsRecorder& r, int n) {
    const DofMap& dofs = scene.model.dofs();
    SystemState state = InitialState(scene.model);
    Eigen::VectorXd W = Eigen::VectorXd::Zero(dofs.n_dofs());
    const int hinge = dofs.node_first(scene.node_index.at("pivot"));
    W[hinge] = rate;
    for (int i = 0; i < n; ++i) {
      if (i > 0) {
        Eigen::VectorXd d = Eigen::VectorXd::Zero(dofs.n_dofs());
        d[hinge] = 0.9;
        ApplyIncrement(scene.model, dofs, d, state);
      }
      std::vector<Eigen::Matrix<double, 6, 1>> reactions(size_t(scene.model.n_nodes()),
                                                         Eigen::Matrix<double, 6, 1>::Zero());
      reactions[size_t(scene.node_index.at("pivot"))] << i, 1, 2, 3, 4, 5;
      r.Record(0.1 * i, state, W, i, 2.0 * i, 3.0 * i, Eigen::Vector3d(i, 0, 0), Eigen::Vector3d(0, 0, 2.0 * i),
               &reactions);
      r.RecordStepSize(i > 0 ? 0.1 : 0.0);
      time.push_back(0.1 * i);
      angle.push_back(0.9 * i);
    }
  }
};

TEST(ResultsRecorder, FilesHoldWhatWasRecordedInSceneCoordinates) {
  const std::string dir = TempDir("files");
  Recorded rec;
  const int n = 9;  // angles to 7.2 rad
  {
    ResultsRecorder r(rec.scene, dir);
    rec.Run(r, n);
    r.Finish("completed");
  }
  h5::Reader h5(dir + "/results.h5");
  EXPECT_EQ(h5.StringAttribute("/", "status"), "completed");
  EXPECT_EQ(h5.StringAttribute("/", "format"), "femb-results");
  const Eigen::VectorXd t = h5.Vector("/time");
  ASSERT_EQ(t.size(), n);
  const std::vector<std::string> names = h5.Strings("/nodes/names");
  const int pivot = int(std::find(names.begin(), names.end(), "pivot") - names.begin());
  const int tip = int(std::find(names.begin(), names.end(), "tip") - names.begin());
  ASSERT_LT(pivot, int(names.size()));
  ASSERT_LT(tip, int(names.size()));
  const Eigen::MatrixXd x = h5.Matrix("/nodes/position"), q = h5.Matrix("/nodes/quaternion");
  const Eigen::MatrixXd v = h5.Matrix("/nodes/velocity"), w = h5.Matrix("/nodes/angular_velocity");
  const Eigen::MatrixXd reaction = h5.Matrix("/nodes/reaction"), joint = h5.Matrix("/nodes/joint_coordinates");
  const Eigen::MatrixXd probes = h5.Matrix("/probes/values");
  const std::vector<std::string> columns = h5.Strings("/probes/names");
  ASSERT_EQ(columns, (std::vector<std::string>{"tip.position.x", "tip.position.y", "tip.position.z", "tip.velocity.x",
                                               "tip.velocity.y", "tip.velocity.z", "tip.rotation.w", "tip.rotation.x",
                                               "tip.rotation.y", "tip.rotation.z", "hinge.joint.0"}));
  const std::vector<std::vector<std::string>> csv = ReadCsv(dir + "/probes.csv");
  ASSERT_EQ(csv.size(), size_t(n + 1));
  EXPECT_EQ(csv[0].front(), "time");
  EXPECT_EQ(csv[0][1], "tip.position.x");
  EXPECT_EQ(csv[0].back(), "external_work");
  for (int i = 0; i < n; ++i) {
    const double a = rec.angle[size_t(i)], c = std::cos(a), s = std::sin(a);
    EXPECT_EQ(t[i], rec.time[size_t(i)]);
    const Eigen::Vector3d x_tip = kPivot + Eigen::Vector3d(c, s, 0);
    const Eigen::Vector3d v_tip = rec.rate * Eigen::Vector3d(-s, c, 0);
    EXPECT_LT((x.row(i).segment<3>(3 * pivot).transpose() - kPivot).norm(), 1e-12) << i;
    EXPECT_LT((x.row(i).segment<3>(3 * tip).transpose() - x_tip).norm(), 1e-12) << i;
    EXPECT_LT((v.row(i).segment<3>(3 * tip).transpose() - v_tip).norm(), 1e-12) << i;
    EXPECT_LT((w.row(i).segment<3>(3 * tip).transpose() - Eigen::Vector3d(0, 0, rec.rate)).norm(), 1e-14) << i;
    // The quaternion of a turn by a about z, w >= 0.
    Eigen::Vector4d qe(std::cos(a / 2), 0, 0, std::sin(a / 2));
    if (qe[0] < 0) qe = -qe;
    EXPECT_LT((q.row(i).segment<4>(4 * tip).transpose() - qe).norm(), 1e-14) << i;
    EXPECT_NEAR(joint(i, 0), a, 1e-14) << i;
    Eigen::Matrix<double, 6, 1> r_expected;
    r_expected << i, 1, 2, 3, 4, 5;
    EXPECT_EQ(reaction.row(i).segment<6>(6 * pivot).transpose(), r_expected) << i;
    // The probes: the same numbers, and probes.csv the same to its printed precision.
    Eigen::VectorXd expected(11);
    expected << x_tip, v_tip, qe, a;
    EXPECT_LT((probes.row(i).transpose() - expected).norm(), 1e-12) << i;
    ASSERT_EQ(csv[size_t(i + 1)].size(), 1u + 11u + 3u);
    EXPECT_DOUBLE_EQ(std::stod(csv[size_t(i + 1)][0]), rec.time[size_t(i)]);
    for (int k = 0; k < 11; ++k) {  // printed to 10 significant digits
      EXPECT_NEAR(std::stod(csv[size_t(i + 1)][size_t(k + 1)]), expected[k],
                  1e-9 * std::max(1.0, std::abs(expected[k])));
    }
    EXPECT_DOUBLE_EQ(std::stod(csv[size_t(i + 1)][12]), i);
    EXPECT_DOUBLE_EQ(std::stod(csv[size_t(i + 1)][14]), 3.0 * i);
  }
  EXPECT_EQ(h5.Vector("/energy/elastic"), 2.0 * Eigen::VectorXd::LinSpaced(n, 0, n - 1));
  // The angular momentum about the global origin: the recorded one (about the model's origin, the
  // pivot here) plus pivot x linear momentum.
  const Eigen::MatrixXd angular = h5.Matrix("/energy/angular_momentum");
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d expected = Eigen::Vector3d(0, 0, 2.0 * i) + kPivot.cross(Eigen::Vector3d(i, 0, 0));
    EXPECT_LT((angular.row(i).transpose() - expected).norm(), 1e-12 * (1 + expected.norm())) << i;
  }
  EXPECT_EQ(h5.Vector("/step_size")[0], 0.0);
  EXPECT_EQ(h5.Vector("/step_size")[1], 0.1);
  fs::remove_all(dir);
}

TEST(ResultsRecorder, WritesDuringTheRunAndLeavesNothingWithoutFinish) {
  const std::string dir = TempDir("flush");
  Recorded rec;
  {
    ResultsRecorder r(rec.scene, dir);
    rec.Run(r, 3);
    r.Flush("running: t = 0.2 of 1 (written during the run)");
    EXPECT_EQ(r.flushes(), 1);
    h5::Reader h5(dir + "/results.h5");
    EXPECT_EQ(h5.StringAttribute("/", "status"), "running: t = 0.2 of 1 (written during the run)");
    EXPECT_EQ(h5.Vector("/time").size(), 3);
    EXPECT_EQ(ReadCsv(dir + "/probes.csv").size(), 4u);
  }
  // Dropped without Finish: the files of the last write stay, no temporary does.
  for (const auto& entry : fs::directory_iterator(dir))
    EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos) << entry.path();
  fs::remove_all(dir);
  const std::string none = TempDir("none");
  {
    ResultsRecorder r(rec.scene, none);
    rec.Run(r, 2);
  }
  EXPECT_FALSE(fs::exists(none + "/probes.csv"));
  EXPECT_FALSE(fs::exists(none + "/results.h5"));
  for (const auto& entry : fs::directory_iterator(none)) ADD_FAILURE() << "left behind: " << entry.path();
  fs::remove_all(none);
}

}  // namespace
}  // namespace femb
