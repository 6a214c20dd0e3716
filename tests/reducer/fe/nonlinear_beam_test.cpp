// Moderate-rotation (von Karman) beams: force = energy gradient and tangent = force derivative
// (central differences), tangent at rest = the linear beam stiffness; a clamped-guided beam with
// its guided end free to slide (no axial force) bends linearly, delta = F L^3 / (12 EI), and
// shortens by 3 delta^2 / (5 L) (inextensible: u' = -v'^2 / 2 integrated over the cubic shape):
// femb's full Newton on the beam model against both closed forms.
#include "reducer/fe/nonlinear_beam.h"

#include <gtest/gtest.h>

#include <random>

#include "reducer/fe/beam_model.h"
#include "test_util.h"

namespace femb {
namespace {

PartSpec Leaf(int elements, const std::string& theory = "euler_bernoulli") {
  return ParsePart(
      "name: leaf\ntype: beam\nmaterial: {E: 2.1e11, nu: 0.3, rho: 7850}\n"
      "section: {shape: rectangle, width: 0.01, height: 0.0005}\n"
      "beam:\n  theory: " +
          theory +
          "\n  orientation: [0, 1, 0]\n"
          "  points: {A: [0, 0, 0], B: [0.05, 0, 0]}\n"
          "  segments: [{from: A, to: B, elements: " +
          std::to_string(elements) +
          "}]\n"
          "interfaces: [{name: A}, {name: B}]\n",
      "leaf.yaml");
}

TEST(VonKarmanBeam, ForceAndTangentMatchFiniteDifferences) {
  for (const std::string theory : {"euler_bernoulli", "timoshenko"}) {
    const VonKarmanBeams beams(Leaf(6, theory));
    const long n = beams.n_dofs();
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> unit(-1, 1);
    Eigen::VectorXd u(n);
    for (long i = 0; i < n; ++i) u[i] = (i % 6 < 3 ? 2e-3 : 0.05) * unit(rng);  // slopes ~0.05: nonlinear
    const Eigen::VectorXd f = beams.Force(u);
    const Eigen::MatrixXd K = Eigen::MatrixXd(beams.Tangent(u));
    Eigen::VectorXd grad(n);
    Eigen::MatrixXd dforce(n, n);
    for (long i = 0; i < n; ++i) {
      const double h = i % 6 < 3 ? 1e-9 : 1e-7;
      Eigen::VectorXd up = u, um = u;
      up[i] += h;
      um[i] -= h;
      grad[i] = (beams.Energy(up) - beams.Energy(um)) / (2 * h);
      dforce.col(i) = (beams.Force(up) - beams.Force(um)) / (2 * h);
    }
    EXPECT_LT((grad - f).norm(), 1e-6 * f.norm()) << theory;
    EXPECT_LT((dforce - K).norm(), 1e-6 * K.norm()) << theory;
    // At rest: the linear beam model's stiffness.
    const FeModel model = BuildBeamModel(Leaf(6, theory));
    EXPECT_LT((Eigen::MatrixXd(beams.Tangent(Eigen::VectorXd::Zero(n))) - Eigen::MatrixXd(model.K)).norm(),
              1e-12 * Eigen::MatrixXd(model.K).norm())
        << theory;
  }
}

TEST(VonKarmanBeam, ClampedGuidedLeafShortensByThreeFifthsDeltaSquaredOverL) {
  // F across the thickness (local z) at B; B slides freely along x, its other DOFs held.
  const int elements = 40;
  const PartSpec part = Leaf(elements);
  const VonKarmanBeams beams(part);
  const double L = 0.05, EI = 2.1e11 * 0.01 * std::pow(0.0005, 3) / 12, F = 10.0;
  std::vector<int> held;
  for (int d = 0; d < 6; ++d) held.push_back(d);         // A: node 0
  for (int d : {1, 3, 4, 5}) held.push_back(6 * 1 + d);  // B: node 1 (the part's second point)
  Eigen::VectorXd f = Eigen::VectorXd::Zero(beams.n_dofs());
  f[6 * 1 + 2] = F;
  const NonlinearStaticResult r =
      SolveNonlinearStatic(beams, SparseMatrix(), held, Eigen::VectorXd::Zero(long(held.size())), f, 10);
  ASSERT_TRUE(r.converged) << r.message;
  for (size_t s = 0; s < r.u.size(); ++s) {
    const double lambda = r.load_factor[s];
    const double delta = r.u[s][6 + 2], shortening = -r.u[s][6];
    const double delta_ref = lambda * F * L * L * L / (12 * EI), shortening_ref = 0.6 * delta * delta / L;
    std::printf("[ info ] F %5.1f N: delta %.5f mm (closed form %.5f), shortening %.6f mm (3 delta^2 / 5L %.6f)\n",
                lambda * F, 1e3 * delta, 1e3 * delta_ref, 1e3 * shortening, 1e3 * shortening_ref);
    // With the element-mean axial strain there is no axial force left to couple them (pointwise
    // the strain locked: 5% at 40 elements): both to 1e-6.
    EXPECT_NEAR(delta, delta_ref, 1e-6 * delta_ref);
    EXPECT_NEAR(shortening, shortening_ref, 1e-6 * shortening_ref);
  }
}

}  // namespace
}  // namespace femb
