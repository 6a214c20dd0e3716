// Modal derivatives validated: a clamped-guided steel leaf (50 x 10 x 0.5 mm, HEX20) pushed across its
// thickness by a force at the guided end, which slides freely along the leaf and does not rotate.
// One superelement with modal derivatives (femb-solve's static analysis, polynomial internal
// force) against femb's full nonlinear model of the same mesh (Green-Lagrange, Newton:
// SolveNonlinearStatic) over the stroke: deflection and axial shortening within 2% at every
// step with the floating frame on the clamped end (the guided end then keeps its local rotation
// at zero); the same body without the polynomial force (linear inside) misses the shortening.
// With the centre-of-mass frame both ends turn by the chord angle (0.09 rad at 10 N) relative to
// the frame, and the polynomial's truncation of those rotations shows (printed, not asserted).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "formats/part_file.h"
#include "formats/superelement_file.h"
#include "reducer/fe/nonlinear_beam.h"
#include "reducer/fe/nonlinear_solid.h"
#include "reducer/fe/solid_model.h"
#include "reducer/reduce_part.h"
#include "solver/analysis/static_analysis.h"
#include "solver/scene/scene_builder.h"

namespace femb {
namespace {

constexpr double kForce = 10.0;  // N: deflection ~5 mm = 10 thicknesses, shortening ~0.3 mm
constexpr int kSteps = 10;

const char* kLeaf =
    "name: leaf\ntype: solid\nunits: SI\nmaterial: {E: 2.1e11, nu: 0.3, rho: 7850}\n"
    "geometry: {shape: box, size: [0.05, 0.01, 0.0005]}\n"
    "mesh: {size: 0.002, order: 2, elements: hexahedra}\n"
    "interfaces: [{name: A, group: xmin}, {name: B, group: xmax}]\n"
    "reduction: {internal_modes: 4, modal_derivatives: {of: static}}\n";

// Guided end: a massless carriage p travels across the leaf (z); B slides on it along x without
// rotating. Interface points are the end faces' centroids (x = 0 / 0.05, y = 0.005, z = 0.00025).
std::string SceneText(const std::string& file, const std::string& internal_force, double z = 0.00025,
                      double y = 0.005) {
  char text[1500];
  std::snprintf(
      text, sizeof text,
      "name: leaf_guided\nunits: SI\nbodies:\n"
      "  - {name: leaf, superelement: %s, nodes: {A: a, B: b}, options: {internal_force: %s}}\n"
      "  - {name: carriage, type: rigid, mass: 1.0e-6, center_of_mass: [0, 0, 0], inertia: [1e-12, 1e-12, 1e-12],\n"
      "     points: {P: [0, 0, 0]}, placement: {position: [0.05, %.17g, %.17g]}, nodes: {P: p}}\n"
      "joints:\n  - {type: clamp, node: a}\n  - {type: prismatic, node: p, axis: [0, 0, 1]}\n"
      "  - {type: prismatic, node: b, parent: p, axis: [1, 0, 0]}\n"
      "loads:\n  - {type: force, node: b, force: [0, 0, %.17g]}\n"
      "analysis: {type: static, end_time: 1, steps: %d}\n",
      file.c_str(), internal_force.c_str(), y, z, kForce, kSteps);
  return text;
}

struct Curve {
  std::vector<double> deflection, shortening;  // of B, per load step
};

Curve Reduced(const std::string& dir, const std::string& file, const std::string& internal_force, double z = 0.00025,
              double y = 0.005) {
  const std::string path = dir + "/scene_" + internal_force + ".yaml";
  std::ofstream(path) << SceneText(file, internal_force, z, y);
  const Scene scene = BuildScene(ReadSceneFile(path));
  SystemState state = InitialState(scene.model);
  const int b = scene.node_index.at("b");
  const Eigen::Vector3d x0 = state.x[size_t(b)];
  StaticOptions options;
  options.steps = kSteps;
  Curve c;
  const StaticResult r = SolveStatic(scene.model, state, options, [&](const StaticStepReport&, const SystemState& s) {
    c.deflection.push_back(s.x[size_t(b)].z() - x0.z());
    c.shortening.push_back(x0.x() - s.x[size_t(b)].x());
  });
  EXPECT_TRUE(r.ok) << r.message;
  return c;
}

TEST(LeafSpring, OneBodyWithModalDerivativesMatchesTheFullNonlinearModel) {
  const std::string dir = ::testing::TempDir() + "leaf_spring";
  std::filesystem::create_directories(dir);
  const PartSpec part = ParsePart(kLeaf, "leaf.yaml");
  for (const std::string frame : {"interface:A", "center_of_mass"}) {
    const ReduceResult reduced =
        ReducePart(ParsePart(kLeaf, "leaf.yaml", {"reduction.floating_frame=" + frame}), nullptr);
    ASSERT_TRUE(reduced.ok) << reduced.message;
    WriteSuperelementFile(reduced.superelement, dir + "/leaf_" + frame.substr(0, 4) + ".h5");
    std::printf("[ info ] superelement (frame %s): %d coordinates (%ld modal derivatives)\n", frame.c_str(),
                reduced.superelement.n_reduced_dofs(), reduced.superelement.n_modal_derivatives);
  }

  // Reference: the full Green-Lagrange model, A clamped, B's u_y and rotations held, u_x free,
  // force on u_z.
  const FeModel model = BuildSolidModel(part);
  const SvkSolidMesh solid(SolidType::kHex20, model.nodes, model.cells, part.material);
  std::vector<int> held;
  for (int d = 0; d < 6; ++d) held.push_back(model.interface_dofs[0][d].value);
  for (int d : {1, 3, 4, 5}) held.push_back(model.interface_dofs[1][d].value);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(model.n_dofs());
  f[model.interface_dofs[1][2].value] = kForce;
  const NonlinearStaticResult full =
      SolveNonlinearStatic(solid, model.mesh_map, held, Eigen::VectorXd::Zero(long(held.size())), f, kSteps);
  ASSERT_TRUE(full.converged) << full.message;

  const Curve poly = Reduced(dir, "leaf_inte.h5", "polynomial"), linear = Reduced(dir, "leaf_inte.h5", "linear");
  const Curve com = Reduced(dir, "leaf_cent.h5", "polynomial");
  ASSERT_EQ(poly.deflection.size(), size_t(kSteps));
  ASSERT_EQ(linear.deflection.size(), size_t(kSteps));
  std::printf(
      "[ info ]  F [N]   full: w, shortening [mm]   1 body + derivatives: error w, s   linear body: error w, s"
      "   centre-of-mass frame: error w, s\n");
  double worst_poly = 0, worst_linear_s = 0;
  for (int s = 0; s < kSteps; ++s) {
    const double w = full.u[size_t(s)][model.interface_dofs[1][2].value];
    const double sh = -full.u[size_t(s)][model.interface_dofs[1][0].value];
    const double ew = std::abs(poly.deflection[size_t(s)] - w) / w, es = std::abs(poly.shortening[size_t(s)] - sh) / sh;
    const double lw = std::abs(linear.deflection[size_t(s)] - w) / w,
                 ls = std::abs(linear.shortening[size_t(s)] - sh) / sh;
    const double cw = std::abs(com.deflection[size_t(s)] - w) / w, cs = std::abs(com.shortening[size_t(s)] - sh) / sh;
    std::printf(
        "[ info ]  %5.1f   %7.4f  %7.5f            %6.2f%%  %6.2f%%               %6.2f%%  %6.2f%%          %6.2f%%  "
        "%6.2f%%\n",
        kForce * (s + 1) / kSteps, 1e3 * w, 1e3 * sh, 100 * ew, 100 * es, 100 * lw, 100 * ls, 100 * cw, 100 * cs);
    worst_poly = std::max({worst_poly, ew, es});
    worst_linear_s = std::max(worst_linear_s, ls);
  }
  EXPECT_LT(worst_poly, 0.02);
  EXPECT_GT(worst_linear_s, 0.05);
}

TEST(LeafSpring, OneBeamBodyWithModalDerivativesMatchesTheFullBeamModel) {
  // The same leaf as a moderate-rotation beam (40 Euler-Bernoulli elements, nonlinear_beam.h):
  // one body with modal derivatives against femb's full Newton on the beam model, which the
  // closed forms delta = F L^3 / 12 EI and shortening 3 delta^2 / 5L confirm
  // (tests/reducer/fe/nonlinear_beam_test.cpp). Within 2% over the stroke.
  const std::string dir = ::testing::TempDir() + "leaf_beam";
  std::filesystem::create_directories(dir);
  const std::string text =
      "name: leaf_beam\ntype: beam\nunits: SI\nmaterial: {E: 2.1e11, nu: 0.3, rho: 7850}\n"
      "section: {shape: rectangle, width: 0.01, height: 0.0005}\n"
      "beam:\n  theory: euler_bernoulli\n  orientation: [0, 1, 0]\n  points: {A: [0, 0, 0], B: [0.05, 0, 0]}\n"
      "  segments: [{from: A, to: B, elements: 40}]\n"
      "interfaces: [{name: A}, {name: B}]\n"
      "reduction: {internal_modes: 4, floating_frame: 'interface:A', modal_derivatives: {of: static}}\n";
  const PartSpec part = ParsePart(text, "leaf_beam.yaml");
  const ReduceResult reduced = ReducePart(part, nullptr);
  ASSERT_TRUE(reduced.ok) << reduced.message;
  ASSERT_TRUE(reduced.superelement.polynomial.has_value());
  WriteSuperelementFile(reduced.superelement, dir + "/leaf_beam.h5");
  std::printf("[ info ] beam superelement: %d coordinates (%ld modal derivatives)\n",
              reduced.superelement.n_reduced_dofs(), reduced.superelement.n_modal_derivatives);
  const VonKarmanBeams beams(part);
  std::vector<int> held;
  for (int d = 0; d < 6; ++d) held.push_back(d);
  for (int d : {1, 3, 4, 5}) held.push_back(6 + d);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(beams.n_dofs());
  f[6 + 2] = kForce;
  const NonlinearStaticResult full =
      SolveNonlinearStatic(beams, SparseMatrix(), held, Eigen::VectorXd::Zero(long(held.size())), f, kSteps);
  ASSERT_TRUE(full.converged) << full.message;
  const Curve poly = Reduced(dir, "leaf_beam.h5", "polynomial", 0.0, 0.0),
              linear = Reduced(dir, "leaf_beam.h5", "linear", 0.0, 0.0);
  double worst = 0, worst_linear_s = 0;
  for (int s = 0; s < kSteps; ++s) {
    const double w = full.u[size_t(s)][6 + 2], sh = -full.u[size_t(s)][6];
    worst =
        std::max({worst, std::abs(poly.deflection[size_t(s)] - w) / w, std::abs(poly.shortening[size_t(s)] - sh) / sh});
    worst_linear_s = std::max(worst_linear_s, std::abs(linear.shortening[size_t(s)] - sh) / sh);
  }
  std::printf(
      "[ info ] beam leaf, one body with modal derivatives: largest error %.3f%% (linear body: shortening %.1f%%)\n",
      100 * worst, 100 * worst_linear_s);
  EXPECT_LT(worst, 0.02);
  EXPECT_GT(worst_linear_s, 0.5);
}

}  // namespace
}  // namespace femb
