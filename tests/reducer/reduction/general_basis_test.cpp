// General deformation bases (thesis 8.2): the pseudo-inverse route gives back
// Craig-Bampton when handed its basis (case m = M = 6N: Guyan; m = 6N < M: with its modes); a
// free-interface basis reproduces the full model's free-free frequencies it contains exactly and
// converges as modes are added; too few shapes to move every interface direction (m < 6N) are
// completed by a constraint on the interface directions they cannot move (case 4).
#include "reducer/reduction/general_basis.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cstdio>
#include <vector>

#include "formats/superelement_checks.h"
#include "reducer/fe/beam_model.h"
#include "reducer/reduction/craig_bampton.h"
#include "reducer/reduction/full_modes.h"
#include "test_util.h"

namespace femb {
namespace {

const std::string kRod =
    test::StraightBeamYaml(0.3, 20, "{shape: circle, diameter: 0.006}", "{E: 2.0e11, nu: 0.3, rho: 7870}",
                           "[{name: A}, {name: B}]", "reduction: {internal_modes: 6}\n");

double Relative(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) { return (a - b).norm() / b.norm(); }

TEST(GeneralBasis, CraigBamptonBasisGivesCraigBamptonBack) {
  const FeModel model = BuildBeamModel(ParsePart(kRod, "rod.yaml"));
  const CraigBamptonResult cb = CraigBamptonReduce(model, 6, nullptr);
  ASSERT_TRUE(cb.ok) << cb.message;
  // Case 3 (m = 6N = 12, M = 18): static and fixed-interface modes. Case 2 (M = 12): static only.
  for (const int modes : {6, 0}) {
    const GeneralBasisResult g = ReduceOnGeneralBasis(model, cb.shapes.leftCols(12 + modes));
    ASSERT_TRUE(g.ok) << g.message;
    EXPECT_EQ(g.interface_rank, 12);
    EXPECT_EQ(g.columns_kept, 12 + modes);  // the 6 rigid fields appended lie in the static modes' span
    const int n = 12 + modes;
    std::printf("[ info ] %d modes: K_r %.2e, M_r %.2e, static shapes %.2e\n", modes,
                Relative(g.K, cb.K.topLeftCorner(n, n)),
                Relative(g.M.topLeftCorner(12, 12), cb.M.topLeftCorner(12, 12)),
                Relative(g.shapes.leftCols(12), cb.shapes.leftCols(12)));
    EXPECT_LT(Relative(g.K.topLeftCorner(12, 12), cb.K.topLeftCorner(12, 12)), 1e-9);
    EXPECT_LT(Relative(g.M.topLeftCorner(12, 12), cb.M.topLeftCorner(12, 12)), 1e-9);
    EXPECT_LT(Relative(g.shapes.leftCols(12), cb.shapes.leftCols(12)), 1e-9);
    for (int k = 0; k < modes; ++k) EXPECT_NEAR(g.lambda[k], cb.lambda[k], 1e-9 * cb.lambda[k]) << k;
  }
}

TEST(GeneralBasis, FreeInterfaceBasisHasTheFullModelsFreeFreeFrequencies) {
  const std::string part = kRod + "";
  const Superelement cb = test::Reduce(part, {"reduction.full_modes=12"});
  const double f_full_7 = cb.full_free_free_frequencies_hz[6 + 6];  // the 7th flexible mode
  double previous = 1e300;
  for (const int k : {4, 8, 12}) {
    const Superelement fi =
        test::Reduce(part, {"reduction.method=free_interface", "reduction.internal_modes=" + std::to_string(k),
                            "reduction.full_modes=12"});
    EXPECT_EQ(fi.provenance.reduction_method, "free_interface");
    EXPECT_EQ(fi.n_reduced_dofs(), 12 + k);
    const SuperelementChecks checks = CheckSuperelement(fi);
    EXPECT_EQ(checks.first_failure(), nullptr) << (checks.first_failure() ? checks.first_failure()->detail : "");
    // Free-free frequencies of the reduced model (6 rigid first) against the full model's.
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(fi.K, fi.M, Eigen::EigenvaluesOnly);
    double worst_included = 0.0;
    for (int j = 0; j < k; ++j) {
      const double f = std::sqrt(std::max(eig.eigenvalues()[6 + j], 0.0)) / (2 * M_PI);
      worst_included = std::max(worst_included, std::abs(f / fi.full_free_free_frequencies_hz[6 + j] - 1));
    }
    const double f7 = std::sqrt(eig.eigenvalues()[6 + 6]) / (2 * M_PI);
    std::printf(
        "[ info ] free-interface, %d modes: the %d included free-free frequencies within %.2e; 7th flexible "
        "%+.3f%% (Craig-Bampton 6 modes: %+.3f%%)\n",
        k, k, worst_included, 100 * (f7 / f_full_7 - 1),
        100 * (std::sqrt(CheckSuperelement(cb).lambda[12]) / (2 * M_PI) / f_full_7 - 1));
    EXPECT_LT(worst_included, 1e-8) << k;
    // Rayleigh-Ritz: never below the full model, and better as modes are added.
    EXPECT_GE(f7, f_full_7 * (1 - 1e-9));
    EXPECT_LE(f7, previous * (1 + 1e-9));
    previous = f7;
  }
}

// Case 4 (m < 6N): four free-free bending modes and the rigid fields move 10 of the rod's 12
// interface coordinates; the two they cannot move (the relative stretch and twist) become the
// constraint C q_int = 0. Reference: the full model's free-free frequencies of those four modes,
// which the reduced model restricted to the constraint's null space must give exactly (it is the
// Rayleigh-Ritz model on the span of the shapes; 1e-8). K and M stay regular (the static modes'
// field on the constrained directions), so the file checks pass.
TEST(GeneralBasis, TooFewShapesToMoveEveryInterfaceDirectionAreConstrained) {
  const FeModel model = BuildBeamModel(ParsePart(kRod, "rod.yaml"));
  Eigen::MatrixXd modes;
  Eigen::VectorXd lambda;
  ASSERT_TRUE(FullFreeFreeFrequencies(model, 10, 1.0, &modes, &lambda).ok);
  const CraigBamptonResult cb = CraigBamptonReduce(model, 0, nullptr);
  ASSERT_TRUE(cb.ok) << cb.message;
  const Eigen::MatrixXd static_modes = cb.shapes.leftCols(12);
  const GeneralBasisResult g = ReduceOnGeneralBasis(model, modes.middleCols(6, 4), &static_modes);
  ASSERT_TRUE(g.ok) << g.message;
  EXPECT_EQ(g.interface_rank, 10);
  ASSERT_EQ(g.interface_constraint.rows(), 2);
  ASSERT_EQ(g.interface_constraint.cols(), 12);
  ASSERT_EQ(g.K.rows(), 12);  // no internal coordinates: 10 shapes, all at the interfaces
  // The constrained directions: the relative u_x and theta_x of A and B (the rod lies along x).
  std::vector<std::vector<int>> directions = g.constraint_direction;
  for (std::vector<int>& d : directions) std::sort(d.begin(), d.end());
  std::sort(directions.begin(), directions.end());
  EXPECT_EQ(directions, (std::vector<std::vector<int>>{{0, 6}, {3, 9}}));
  // Once the rotation columns are divided by the part's size (0.3 m): the rows (A.u_x - B.u_x)
  // and (A.theta_x - B.theta_x), of unit length, in some order and sign.
  Eigen::VectorXd unscale = Eigen::VectorXd::Ones(12);
  for (int k = 0; k < 2; ++k) unscale.segment<3>(6 * k + 3).setConstant(1.0 / g.constraint_length);
  EXPECT_NEAR(g.constraint_length, 0.3, 1e-12);
  const Eigen::MatrixXd Cs = g.interface_constraint * unscale.asDiagonal();
  for (int i = 0; i < 2; ++i) {
    const int c = std::abs(Cs(i, 0)) > 0.5 ? 0 : 3;
    Eigen::RowVectorXd expected = Eigen::RowVectorXd::Zero(12);
    expected[c] = Cs(i, c) > 0 ? M_SQRT1_2 : -M_SQRT1_2;
    expected[c + 6] = -expected[c];
    EXPECT_LT((Cs.row(i) - expected).norm(), 1e-10) << Cs.row(i);
  }
  // The rigid motions are free: C Phi_rig0 = 0 (interface rows of the rigid fields).
  const Eigen::MatrixXd rigid = InterfaceRows(model) * RigidFields(model);
  EXPECT_LT((g.interface_constraint * rigid).norm() / rigid.norm(), 1e-10);
  // Free-free frequencies on the constraint's null space.
  Eigen::FullPivLU<Eigen::MatrixXd> lu(g.interface_constraint);
  const Eigen::MatrixXd N = lu.kernel();
  ASSERT_EQ(N.cols(), 10);
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(N.transpose() * g.K * N, N.transpose() * g.M * N,
                                                                Eigen::EigenvaluesOnly);
  double worst = 0.0;
  for (int j = 0; j < 4; ++j) worst = std::max(worst, std::abs(eig.eigenvalues()[6 + j] / lambda[6 + j] - 1));
  std::printf(
      "[ info ] 4 bending shapes, constraint C (2 x 12): free-free eigenvalues within %.2e of the full model's\n",
      worst);
  EXPECT_LT(worst, 1e-8);
  for (int j = 0; j < 6; ++j) EXPECT_LT(std::abs(eig.eigenvalues()[j]), 1e-8 * lambda[6]) << j;
  // Without the constraint K and M are regular but for the 6 rigid motions.
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> m_eig(g.M, Eigen::EigenvaluesOnly);
  EXPECT_GT(m_eig.eigenvalues()[0], 0.0);
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> k_eig(g.K, g.M, Eigen::EigenvaluesOnly);
  EXPECT_LT(std::abs(k_eig.eigenvalues()[5]), 1e-8 * k_eig.eigenvalues().maxCoeff());
  EXPECT_GT(k_eig.eigenvalues()[6], 1e-6 * k_eig.eigenvalues().maxCoeff());
}

// A solid tube with a distributing (RBE3) interface: the interface rows are the RBE3 weights,
// and the free-interface superelement passes every file check.
TEST(GeneralBasis, FreeInterfaceSolidWithDistributingInterface) {
  const Superelement fi = test::Reduce(
      "name: t\ntype: solid\nmaterial: {E: 2.1e11, nu: 0.3, rho: 7850}\n"
      "geometry: {shape: tube, radius: 0.05, inner_radius: 0.03, length: 0.3}\nmesh: {size: 0.02, order: 2}\n"
      "interfaces: [{name: bottom, group: bottom}, {name: top, group: top, coupling: rbe3}]\n"
      "reduction: {method: free_interface, internal_modes: 6, floating_frame: mean_axes, full_modes: 6}\n");
  const SuperelementChecks checks = CheckSuperelement(fi);
  EXPECT_EQ(checks.first_failure(), nullptr) << (checks.first_failure() ? checks.first_failure()->detail : "");
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(fi.K, fi.M, Eigen::EigenvaluesOnly);
  for (int j = 0; j < 6; ++j) {
    const double f = std::sqrt(eig.eigenvalues()[6 + j]) / (2 * M_PI);
    EXPECT_NEAR(f, fi.full_free_free_frequencies_hz[6 + j], 1e-7 * fi.full_free_free_frequencies_hz[6 + j]) << j;
  }
}

}  // namespace
}  // namespace femb
