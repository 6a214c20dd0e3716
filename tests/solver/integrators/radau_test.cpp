// The Radau IIA step's iteration matrix (solver/integrators/radau.cpp) against central differences
// of its three stages' residuals (RadauStageResiduals) along each stage acceleration, at stage
// accelerations off the step's solution, as Newton's iterates are. The matrix is
// -d(residual)/dA with block (i, j) = delta_ij M_i + h a_ij C_i + h^2 (a^2)_ij K_i from stage i's
// own K, C and M (generalized-alpha's), the constraint rows scaled by 1 / h^2.
//
// What it leaves out, by design:
// - by default (full_inertia_tangent off), the configuration derivative of the quadratic velocity
//   terms: of the order (Omega / omega)^2 of the stiffness of a mode omega in a body turning at
//   Omega (a flexible crank's first mode at 150 rad/s: 2e-5 of its entry), independent of the
//   step since the stiffness column is the largest;
// - a rotation triple's stage coordinates Theta_i are the fixed point of Theta = h a J_l^-1(Theta) V
//   and turn the stage by J_l(Theta_i) dTheta, where the matrix takes h^2 (a^2) and the identity:
//   O(omega h) of those columns' kept terms, falling with the step.
// Measured here (the largest column error over the largest column; default / full inertia
// tangent, at 1 ms and 0.1 ms steps):
//   - slider-crank: 2.4e-5, 2.0e-5 / 4.8e-6, 2.3e-7;
//   - free tube spinning at 50 rad/s: 3.7e-5, 8.3e-6 / 4.5e-6, 2.1e-7;
//   - four-bar through its closed loop: 3.4e-6, 2.0e-6 (both), the free node's rotation columns
//     in the constraint rows.
// The bound 1e-4 leaves these and catches a wrong term: tried, a transposed tableau a in the C
// blocks (3.9e-4 to 8.9e-4), a transposed a^2 in the K blocks, and a multiplier's column in every
// stage's equations instead of its own (the closed loop) each fail it.
// Differences with steps of 1e-2 of each acceleration's scale: the residual is quadratic in the
// stage velocities, on which central differences are exact, while 1e-4 of it moves a 0.1 ms
// step's stages by round-off (the constraint rows, scaled by 1 / h^2, were then off by 6e-5 of
// the largest column).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "formats/scene_file.h"
#include "formats/superelement_file.h"
#include "solver/analysis/dynamic_analysis.h"
#include "solver/analysis/dynamic_step.h"
#include "solver/scene/scene_builder.h"
#include "test_util.h"

namespace femb {
namespace {

using dynamic_internal::BodyWorkspace;
using dynamic_internal::RadauStageResiduals;

constexpr double kBound = 1e-4;

// The iteration matrix at stage accelerations off the solution of a step of h from s0 (each the
// state's accelerations and multipliers moved by a random 1% of their scale: the entry itself, at
// least 1e-3 of the largest of its kind) against central differences (steps 1e-2 of each entry's
// scale): max_j |S_j - D_j| / max_j |D_j| over the 3 n columns.
double MatrixError(const SystemModel& model, const DofMap& dofs, const DynamicState& s0, double h, bool full) {
  DynamicOptions options;
  options.full_inertia_tangent = full;
  const int N = dofs.n_dofs();
  Eigen::VectorXd a = s0.Wdot;
  if (dofs.n_multipliers() > 0) a.tail(dofs.n_multipliers()) = s0.config.lambda;
  double largest_a = 0.0, largest_lambda = 0.0;
  for (int j = 0; j < N; ++j) {
    double& largest = dofs.multiplier(j) ? largest_lambda : largest_a;
    largest = std::max(largest, std::abs(a[j]));
  }
  Eigen::VectorXd scale(N);
  for (int j = 0; j < N; ++j)
    scale[j] = std::max({std::abs(a[j]), 1e-3 * (dofs.multiplier(j) ? largest_lambda : largest_a), 1e-9});
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::array<Eigen::VectorXd, 3> A;
  for (Eigen::VectorXd& Ai : A) {
    Ai = a;
    for (int j : dofs.solved()) Ai[j] += 0.01 * scale[j] * u(rng);
  }
  BodyWorkspace work;
  Eigen::MatrixXd S;
  RadauStageResiduals(model, dofs, options, s0, h, A, work, &S);
  const std::vector<int>& solved = dofs.solved();
  const int n = int(solved.size());
  Eigen::MatrixXd D(3 * n, 3 * n);
  for (int i = 0; i < 3; ++i) {
    for (int k = 0; k < n; ++k) {
      const double eps = 1e-2 * scale[solved[size_t(k)]];
      Eigen::VectorXd r[2];
      for (int side = 0; side < 2; ++side) {
        std::array<Eigen::VectorXd, 3> Ad = A;
        Ad[size_t(i)][solved[size_t(k)]] += side ? eps : -eps;
        BodyWorkspace w;
        r[side] = RadauStageResiduals(model, dofs, options, s0, h, Ad, w);
      }
      D.col(i * n + k) = -(r[1] - r[0]) / (2 * eps);
    }
  }
  EXPECT_TRUE(S.allFinite() && D.allFinite());
  double largest = 0.0, worst = 0.0;
  for (int c = 0; c < 3 * n; ++c) largest = std::max(largest, D.col(c).norm());
  for (int c = 0; c < 3 * n; ++c) worst = std::max(worst, (S.col(c) - D.col(c)).norm() / largest);
  return worst;
}

// The matrix's error after 20 steps of h from `start`, with and without the quadratic velocity
// terms' configuration derivative (full_inertia_tangent); with it, the error falls with the step.
void CheckAfterSteps(const SystemModel& model, const DynamicState& start, const std::string& what) {
  const DofMap dofs(model);
  for (bool full : {false, true}) {
    double error[2];
    for (int i = 0; i < 2; ++i) {
      const double h = i == 0 ? 1e-3 : 1e-4;
      error[i] = MatrixError(model, dofs, test::AdvanceSteps(model, start, Integrator::kRadau, h, 20, 1e-10), h, full);
      std::printf("[ info ] %s, h = %.3g, %s: the iteration matrix off the differences by %.2e of the largest column\n",
                  what.c_str(), h, full ? "full inertia tangent" : "default", error[i]);
      EXPECT_LT(error[i], kBound) << what << ", h = " << h;
    }
    if (full) {
      EXPECT_LT(error[1], error[0]) << what << ": the gap does not fall with the step";
    }
  }
}

// The slider-crank of test_util: a flexible crank driven at 150 rad/s, a rod of two stiffened tube
// bodies (exact inertia), a slider on a prismatic joint; gravity. A tree of joints: no multipliers.
TEST(RadauIterationMatrix, SliderCrankMatchesDifferences) {
  const Superelement crank = test::TubeSegment(0.15, 4, true), rod = test::TubeSegment(0.25, 4, true);
  const SystemModel model = test::SliderCrankModel(crank, rod, 0.15, 0.25);
  const DynamicState start =
      InitialDynamicState(model, InitialState(model), Eigen::VectorXd::Zero(model.dofs().n_dofs()));
  CheckAfterSteps(model, start, "slider-crank");
}

// A spinning free tube (one body on two free nodes: the rotation triples' columns), tumbling.
TEST(RadauIterationMatrix, FreeSpinningTubeMatchesDifferences) {
  const Superelement tube = test::TubeSegment(0.3, 6, true);
  SystemModel model;
  AddNode(model, "a", Eigen::Vector3d::Zero());
  AddNode(model, "b", Eigen::Vector3d(0.3, 0, 0));
  model.bodies.emplace_back(tube, SuperelementOptions{}, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  model.body_nodes.push_back({0, 1});
  model.Number();
  const DofMap dofs(model);
  const Eigen::Vector3d spin(0, 5, 50);
  Eigen::VectorXd W0 = Eigen::VectorXd::Zero(dofs.n_dofs());
  for (int k = 0; k < model.n_nodes(); ++k) {
    W0.segment<3>(dofs.node_first(k)) = spin.cross(model.node_x0[k]);
    W0.segment<3>(dofs.node_first(k) + 3) = spin;
  }
  const DynamicState start = InitialDynamicState(model, InitialState(model), W0);
  CheckAfterSteps(model, start, "free tube spinning at 50 rad/s");
}

// A closed loop: a planar four-bar, rigid crank (0.1 m, driven at 20 rad/s) and rocker (0.1 m)
// and a stiffened tube coupler (0.4 m); the rocker's tip hangs on the rocker and on the coupler,
// so that revolute is cut (its constraint equations and multipliers are unknowns of each stage,
// their rows scaled by 1 / h^2).
TEST(RadauIterationMatrix, ClosedLoopMatchesDifferences) {
  const std::string dir = ::testing::TempDir() + "radau_four_bar";
  std::filesystem::create_directories(dir);
  WriteSuperelementFile(test::TubeSegment(0.4, 6, true), dir + "/coupler.h5");
  const std::string link =
      "type: rigid, mass: 0.07, inertia: [1.0e-6, 6.0e-5, 6.0e-5], center_of_mass: [0.05, 0, 0], "
      "points: {P: [0, 0, 0], Q: [0.1, 0, 0]}";
  const std::string up = "rotation: [0, 0, 1.5707963267948966]";
  std::ofstream(dir + "/scene.yaml")
      << "name: four_bar\nunits: SI\nbodies:\n"
      << "  - {name: crank, " << link << ", placement: {" << up << "}, nodes: {P: A, Q: B1}}\n"
      << "  - {name: coupler, superelement: coupler.h5, placement: {position: [0, 0.1, 0]}, nodes: {A: B2, B: C1}}\n"
      << "  - {name: rocker, " << link << ", placement: {position: [0.4, 0, 0], " << up << "}, nodes: {P: D, Q: C2}}\n"
      << "joints:\n"
         "  - {type: revolute, node: A, axis: [0, 0, 1], prescribed: crank}\n"
         "  - {type: revolute, node: B2, parent: B1, axis: [0, 0, 1]}\n"
         "  - {type: revolute, node: D, axis: [0, 0, 1]}\n"
         "  - {type: revolute, node: C2, parent: C1, axis: [0, 0, 1]}\n"
         "functions:\n  crank: {type: linear, slope: 20}\n"
         "loads:\n  - {type: gravity, g: [0, -9.81, 0]}\n"
         "analysis: {type: dynamic, end_time: 0.01, step: 1e-4}\n";
  const Scene scene = BuildScene(ReadSceneFile(dir + "/scene.yaml"));
  ASSERT_EQ(scene.model.cut_joints.size(), 1u);
  const DofMap dofs(scene.model);
  ASSERT_GT(dofs.n_multipliers(), 0);
  const DynamicState start =
      InitialDynamicState(scene.model, InitialState(scene.model), Eigen::VectorXd::Zero(dofs.n_dofs()));
  CheckAfterSteps(scene.model, start, "four-bar, closed loop");
}

}  // namespace
}  // namespace femb
