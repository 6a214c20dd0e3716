// MBDyn's modal element file (inspect/mbdyn_export.h), read back by a small reader of its own
// that follows the record groups as MBDyn parses them (header, node list, coordinates, one block
// of 6 values per node for each mode, N x N matrices, global inertia, invariants 3, 4, 8, 5, 9):
//  - the free-floating body assembled from the file alone (record 12's rigid inertia, the modal
//    mass and stiffness, Inv3 and Inv4 coupling them) has femb's reduced free-free frequencies
//    (the same model in other coordinates: to 1e-9);
//  - a cantilever clamped at the root FEM node and loaded at the tip through the file's shapes
//    deflects as femb's reduced model does (to 1e-9), and as Euler-Bernoulli beam theory says
//    (PL^3 / 3EI, within 3% for this stubby TET10 bar);
//  - the invariants agree with each other as their definitions say: Inv8's skew part is Inv4,
//    Inv5 is skew in its modes, the trace of Inv9 is -2 x the modal mass (solid: translations).
#include "inspect/mbdyn_export.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Dense>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "test_util.h"

namespace femb {
namespace {

namespace fs = std::filesystem;

// The file as MBDyn reads it: every record group's whitespace-separated tokens.
struct FemFile {
  std::map<int, std::vector<std::string>> records;
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  // from the comment lines (frame axes in part axes)
  int nodes = 0, modes = 0;
  std::vector<double> Numbers(int record) const {
    std::vector<double> v;
    for (const std::string& t : records.at(record)) v.push_back(std::stod(t));
    return v;
  }
};

FemFile ReadFem(const std::string& path) {
  FemFile f;
  std::ifstream in(path);
  std::string line;
  int record = 0;
  while (std::getline(in, line)) {
    if (line.rfind("** RECORD GROUP ", 0) == 0) {
      record = std::stoi(line.substr(16));
      EXPECT_EQ(f.records.count(record), 0u) << "record " << record << " twice";
      f.records[record];
      continue;
    }
    if (line.rfind("** frame axis ", 0) == 0) {
      const int a = line[14] - 'x';
      std::istringstream s(line.substr(line.find(':') + 1));
      s >> f.axes(0, a) >> f.axes(1, a) >> f.axes(2, a);
      continue;
    }
    if (line.rfind("**", 0) == 0) continue;  // comments, and each mode's "NORMAL MODE SHAPE #" line
    std::istringstream s(line);
    for (std::string t; s >> t;) f.records[record].push_back(t);
  }
  const std::vector<std::string>& h = f.records.at(1);
  EXPECT_EQ(h.size(), 6u);
  EXPECT_EQ(h[0], "REV0");
  f.nodes = std::stoi(h[1]);
  f.modes = std::stoi(h[2]);
  return f;
}

const char* kBar =
    "name: bar\ntype: solid\nunits: SI\nmaterial: {E: 2.1e11, nu: 0.3, rho: 7850}\n"
    "geometry: {shape: box, size: [0.4, 0.04, 0.02]}\nmesh: {size: 0.02, order: 2}\n"
    "interfaces: [{name: root, group: xmin, coupling: rbe3}, {name: tip, group: xmax, coupling: rbe3}]\n"
    "reduction: {internal_modes: 6}\n";

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

class MbdynExportTest : public ::testing::TestWithParam<const char*> {};

TEST_P(MbdynExportTest, TheFileHoldsFembsReducedModel) {
  const Superelement se = test::Reduce(kBar, {std::string("reduction.floating_frame=") + GetParam()});
  const fs::path path = fs::temp_directory_path() / ("femb_mbdyn_" + std::to_string(::getpid()) + ".fem");
  const MbdynExport summary = WriteMbdynFem(se, path.string(), true);
  const FemFile f = ReadFem(path.string());
  const int n_nodes = 2 + int(se.visualization->nodes.rows()), N = se.n_reduced_dofs() - 6;
  ASSERT_EQ(f.nodes, n_nodes);
  ASSERT_EQ(f.modes, N);
  EXPECT_EQ(summary.modes, N);
  EXPECT_TRUE(summary.invariants);
  // Layout: sizes of every record group.
  ASSERT_EQ(f.records.at(2).size(), size_t(n_nodes));
  EXPECT_EQ(f.records.at(2)[0], "root");
  EXPECT_EQ(f.records.at(2)[1], "tip");
  for (int r : {5, 6, 7}) ASSERT_EQ(f.records.at(r).size(), size_t(n_nodes));
  ASSERT_EQ(f.records.at(8).size(), size_t(6 * n_nodes * N));
  for (int r : {9, 10}) ASSERT_EQ(f.records.at(r).size(), size_t(N * N));
  ASSERT_EQ(f.records.at(12).size(), 13u);
  for (int r : {14, 15}) ASSERT_EQ(f.records.at(r).size(), size_t(3 * N));
  ASSERT_EQ(f.records.at(16).size(), size_t(9 * N));
  ASSERT_EQ(f.records.at(17).size(), size_t(3 * N * N));
  ASSERT_EQ(f.records.at(18).size(), size_t(9 * N * N));
  const std::vector<double> x = f.Numbers(5), y = f.Numbers(6), z = f.Numbers(7), shapes = f.Numbers(8);
  const Eigen::MatrixXd Mm = Eigen::Map<const Eigen::MatrixXd>(f.Numbers(9).data(), N, N);
  const Eigen::MatrixXd Km = Eigen::Map<const Eigen::MatrixXd>(f.Numbers(10).data(), N, N);
  const std::vector<double> g = f.Numbers(12);
  const double m = g[0];
  const Eigen::Vector3d c(g[1], g[2], g[3]);
  Eigen::Matrix3d Jc;
  for (int i = 0; i < 9; ++i) Jc(i / 3, i % 3) = g[size_t(4 + i)];
  const std::vector<double> inv3 = f.Numbers(14), inv4 = f.Numbers(15), inv8 = f.Numbers(16), inv5 = f.Numbers(17),
                            inv9 = f.Numbers(18);
  // Node k's 6 x N shapes and its rigid-body block [1, -x~; 0, 1] in frame axes.
  auto shape = [&](int k) {
    Eigen::MatrixXd s(6, N);
    for (int j = 0; j < N; ++j)
      for (int i = 0; i < 6; ++i) s(i, j) = shapes[size_t((j * n_nodes + k) * 6 + i)];
    return s;
  };
  auto rigid = [&](int k) {
    Eigen::Matrix<double, 6, 6> b = Eigen::Matrix<double, 6, 6>::Identity();
    b.block<3, 3>(0, 3) = -Skew(Eigen::Vector3d(x[size_t(k)], y[size_t(k)], z[size_t(k)]));
    return b;
  };
  // 1. The free body from the file: coordinates (rigid translation, rotation about the modal
  // node, modal), mass [[m, -m c~, Inv3], [m c~, J_o, Inv4], [., ., M]], stiffness diag(0, K).
  const int n = 6 + N;
  Eigen::MatrixXd Mt = Eigen::MatrixXd::Zero(n, n), Kt = Eigen::MatrixXd::Zero(n, n);
  Mt.topLeftCorner(3, 3) = m * Eigen::Matrix3d::Identity();
  Mt.block(0, 3, 3, 3) = -m * Skew(c);
  Mt.block(3, 0, 3, 3) = m * Skew(c);
  Mt.block(3, 3, 3, 3) = Jc - m * Skew(c) * Skew(c);
  for (int a = 0; a < 3; ++a)
    for (int j = 0; j < N; ++j) {
      Mt(a, 6 + j) = Mt(6 + j, a) = inv3[size_t(a * N + j)];
      Mt(3 + a, 6 + j) = Mt(6 + j, 3 + a) = inv4[size_t(a * N + j)];
    }
  Mt.bottomRightCorner(N, N) = Mm;
  Kt.bottomRightCorner(N, N) = Km;
  const Eigen::VectorXd from_file =
      Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd>(Kt, Mt, Eigen::EigenvaluesOnly).eigenvalues();
  const Eigen::VectorXd femb =
      Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd>(se.K, se.M, Eigen::EigenvaluesOnly).eigenvalues();
  const double scale = femb.cwiseAbs().maxCoeff();
  const double frequencies = (from_file.tail(N) - femb.tail(N)).cwiseQuotient(femb.tail(N)).cwiseAbs().maxCoeff();
  std::printf("[ info ] %s: %d modes, %d nodes; free-free eigenvalues from the file vs femb %.2e (rigid %.1e)\n",
              GetParam(), N, n_nodes, frequencies, from_file.head(6).cwiseAbs().maxCoeff() / scale);
  EXPECT_LT(frequencies, 1e-9);
  EXPECT_LT(from_file.head(6).cwiseAbs().maxCoeff(), 1e-9 * scale);
  // 2. Clamped at the root node, 100 N along z at the tip node.
  const Eigen::Matrix3d A = f.axes;
  Eigen::MatrixXd C(6, n);
  C << rigid(0), shape(0);
  Eigen::MatrixXd Bt(6, n);
  Bt << rigid(1), shape(1);
  Eigen::VectorXd load = Eigen::VectorXd::Zero(6);
  load.head(3) = A.transpose() * Eigen::Vector3d(0, 0, 100);
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(n + 6, n + 6);
  S.topLeftCorner(n, n) = Kt;
  S.block(0, n, n, 6) = C.transpose();
  S.block(n, 0, 6, n) = C;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n + 6);
  rhs.head(n) = Bt.transpose() * load;
  const Eigen::VectorXd solution = S.fullPivLu().solve(rhs);
  const Eigen::Vector3d tip_file = A * (Bt * solution.head(n)).head(3);
  const Eigen::MatrixXd K_ff = se.K.bottomRightCorner(se.n_reduced_dofs() - 6, se.n_reduced_dofs() - 6);
  Eigen::VectorXd f_f = Eigen::VectorXd::Zero(K_ff.rows());
  f_f(2) = 100.0;  // tip u_z
  const Eigen::Vector3d tip_femb = K_ff.ldlt().solve(f_f).head(3);
  const double beam = 100.0 * std::pow(0.4, 3) / (3 * 2.1e11 * 0.04 * std::pow(0.02, 3) / 12);
  std::printf("[ info ] tip deflection: file %.9e, femb %.9e, beam theory %.6e m\n", tip_file.z(), tip_femb.z(), beam);
  EXPECT_LT((tip_file - tip_femb).norm(), 1e-9 * tip_femb.norm());
  EXPECT_NEAR(tip_file.z(), beam, 0.03 * beam);
  // 3. The invariants' own relations.
  double skew8 = 0, skew5 = 0, trace9 = 0, scale4 = 0;
  for (int j = 0; j < N; ++j) {
    Eigen::Matrix3d I8;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) I8(a, b) = inv8[size_t(a * 3 * N + 3 * j + b)];
    const Eigen::Vector3d w(I8(1, 2) - I8(2, 1), I8(2, 0) - I8(0, 2), I8(0, 1) - I8(1, 0));
    const Eigen::Vector3d i4(inv4[size_t(j)], inv4[size_t(N + j)], inv4[size_t(2 * N + j)]);
    skew8 = std::max(skew8, (w - i4).norm());
    scale4 = std::max(scale4, i4.norm());
    for (int k = 0; k < N; ++k) {
      double trace = 0;
      for (int a = 0; a < 3; ++a) {
        skew5 = std::max(skew5, std::abs(inv5[size_t(a * N * N + j * N + k)] + inv5[size_t(a * N * N + k * N + j)]));
        trace += inv9[size_t(a * 3 * N * N + 3 * (j * N + k) + a)];
      }
      trace9 = std::max(trace9, std::abs(trace + 2 * Mm(j, k)));
    }
  }
  std::printf("[ info ] Inv8 skew vs Inv4 %.1e (of %.2e), Inv5 skew %.1e, Inv9 trace + 2 M %.1e\n", skew8, scale4,
              skew5, trace9);
  EXPECT_LT(skew8, 1e-9 * std::max(scale4, m * 0.4));
  EXPECT_LT(skew5, 1e-12);
  EXPECT_LT(trace9, 1e-9);
  fs::remove(path);
}

INSTANTIATE_TEST_SUITE_P(Frames, MbdynExportTest, ::testing::Values("center_of_mass", "mean_axes", "interface:root"));

TEST(MbdynExport, AConstrainedBasisIsOneLine) {
  Superelement se = test::Reduce(kBar);
  se.interface_constraint = Eigen::MatrixXd::Identity(1, 12);
  const std::string m = test::ThrownMessage([&] { WriteMbdynFem(se, "/tmp/unused.fem", false); });
  EXPECT_NE(m.find("moves only some interface directions"), std::string::npos) << m;
  EXPECT_FALSE(fs::exists("/tmp/unused.fem"));
}

}  // namespace
}  // namespace femb
