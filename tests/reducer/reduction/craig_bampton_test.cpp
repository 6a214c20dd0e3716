// Craig-Bampton reduction of beams against beam theory and the unreduced model.
#include "reducer/reduction/craig_bampton.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>

#include "reducer/fe/beam_model.h"
#include "reducer/fe/beam_section.h"
#include "reducer/linalg/generalized_eigen.h"
#include "test_util.h"

namespace femb {
namespace {

const char* kSteel = "{E: 2.0e11, nu: 0.3, rho: 7870}";
const char* kRod = "{shape: circle, diameter: 0.006}";
constexpr double kL = 0.3, kE = 2.0e11, kRho = 7870, kD = 0.006;
const double kA = M_PI * kD * kD / 4, kI = M_PI * std::pow(kD, 4) / 64;

// Clamped-free cantilever: the fixed-interface modes of a part whose only interface is the
// clamped end ARE the cantilever modes. Euler-Bernoulli: f_n = (beta_n L)^2 / (2 pi L^2) sqrt(EI / rho A).
void ExpectCantileverFrequencies(const std::string& theory, double tolerance) {
  const Superelement se =
      test::Reduce(test::StraightBeamYaml(kL, 20, kRod, kSteel, "[{name: A}]", "reduction: {internal_modes: 6}\n"),
                   {"beam.theory=" + theory});
  const double beta_L[3] = {1.8751, 4.6941, 7.8548};
  for (int n = 0; n < 3; ++n) {
    const double exact = beta_L[n] * beta_L[n] / (2 * M_PI * kL * kL) * std::sqrt(kE * kI / (kRho * kA));
    // Circular section: each bending frequency appears twice (planes x-y and x-z).
    EXPECT_NEAR(se.internal_frequencies_hz[2 * n], exact, tolerance * exact) << theory << " mode " << n + 1;
    EXPECT_NEAR(se.internal_frequencies_hz[2 * n + 1], exact, tolerance * exact) << theory << " mode " << n + 1;
  }
}

TEST(CraigBampton, CantileverFrequenciesMatchEulerBernoulliWithin0p5Percent) {
  ExpectCantileverFrequencies("euler_bernoulli", 0.005);
  // Shear and rotary inertia lower the third mode by ~0.1% at L/d = 50: still within 0.5%.
  ExpectCantileverFrequencies("timoshenko", 0.005);
}

TEST(CraigBampton, StaticTipDeflectionIsExact) {
  // Static condensation is exact for loads on interface nodes: clamp A, load B.
  for (const std::string theory : {"euler_bernoulli", "timoshenko"}) {
    const Superelement se = test::Reduce(
        test::StraightBeamYaml(kL, 10, kRod, kSteel, "[{name: A}, {name: B}]", "reduction: {internal_modes: 3}\n"),
        {"beam.theory=" + theory});
    const Eigen::MatrixXd K_BB = se.K.block(6, 6, 6, 6);  // node B with node A clamped, modes at rest
    // Internal modes are K-orthogonal to the interface coordinates, so they do not move here.
    const double P = 10.0;
    Eigen::VectorXd f = Eigen::VectorXd::Zero(6);
    f[1] = P;
    const Eigen::VectorXd u = K_BB.ldlt().solve(f);
    double expected = P * kL * kL * kL / (3 * kE * kI);
    if (theory == "timoshenko") {
      const double nu = 0.3, k = 6 * (1 + nu) / (7 + 6 * nu), G = kE / (2 * (1 + nu));
      expected += P * kL / (k * G * kA);
    }
    EXPECT_NEAR(u[1], expected, 1e-9 * expected) << theory;
    EXPECT_NEAR(u[5], P * kL * kL / (2 * kE * kI), 1e-9 * u[5]) << theory;  // tip slope PL^2/2EI
  }
}

TEST(CraigBampton, FreeFreeModelHasSixRigidModesAndTheBeamsMassProperties) {
  const Superelement se = test::Reduce(
      test::StraightBeamYaml(kL, 10, kRod, kSteel, "[{name: A}, {name: B}]", "reduction: {internal_modes: 4}\n"));
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(se.K, se.M);
  const Eigen::VectorXd lambda = eig.eigenvalues();
  int rigid = 0;
  for (int k = 0; k < lambda.size(); ++k) rigid += std::abs(lambda[k]) < 1e-8 * lambda.cwiseAbs().maxCoeff();
  EXPECT_EQ(rigid, 6);
  EXPECT_GT(lambda[6], 1e3 * std::abs(lambda[5]));
  // Solid cylinder: m = rho A L, I_axis = m r^2 / 2, I_transverse = m L^2 / 12 + m r^2 / 4.
  const double m = kRho * kA * kL, r = kD / 2;
  EXPECT_NEAR(se.mass_properties.mass, m, 1e-12 * m);
  EXPECT_LT((se.mass_properties.center_of_mass - Eigen::Vector3d(kL / 2, 0, 0)).norm(), 1e-12);
  const Eigen::Matrix3d expected =
      Eigen::Vector3d(m * r * r / 2, m * kL * kL / 12 + m * r * r / 4, m * kL * kL / 12 + m * r * r / 4).asDiagonal();
  EXPECT_LT((se.mass_properties.inertia_com - expected).norm(), 1e-10 * expected.norm());
}

TEST(CraigBampton, ReducedMatricesAreTheProjectionOnTheBasis) {
  PartSpec part = ParsePart(test::StraightBeamYaml(kL, 8, kRod, kSteel, "[{name: A}, {name: B}]"), "t.yaml");
  const FeModel model = BuildBeamModel(part);
  const CraigBamptonResult cb = CraigBamptonReduce(model, 5, nullptr);
  ASSERT_TRUE(cb.ok) << cb.message;
  const Eigen::MatrixXd K = cb.shapes.transpose() * (model.K * cb.shapes);
  const Eigen::MatrixXd M = cb.shapes.transpose() * (model.M * cb.shapes);
  EXPECT_LT((K - cb.K).norm(), 1e-10 * K.norm());
  EXPECT_LT((M - cb.M).norm(), 1e-10 * M.norm());
  // Internal modes are mass-normalized and K-orthogonal to the constraint modes.
  EXPECT_LT((cb.M.bottomRightCorner(5, 5) - Eigen::MatrixXd::Identity(5, 5)).norm(), 1e-10);
  EXPECT_LT(cb.K.topRightCorner(12, 5).norm(), 1e-8 * K.norm());
}

TEST(CraigBampton, SparseLanczosAgreesWithDenseSolver) {
  // 200 elements: 1188 interior DOFs, beyond the dense limit, so shift-invert Lanczos on the
  // CHOLMOD factor runs; compare with the dense generalized eigen solver on the same matrices.
  PartSpec part = ParsePart(test::StraightBeamYaml(kL, 200, kRod, kSteel, "[{name: A}, {name: B}]"), "t.yaml");
  const FeModel model = BuildBeamModel(part);
  const CraigBamptonResult sparse = CraigBamptonReduce(model, 12, nullptr, /*dense_limit=*/200);
  const CraigBamptonResult dense = CraigBamptonReduce(model, 12, nullptr, /*dense_limit=*/100000);
  ASSERT_TRUE(sparse.ok && dense.ok);
  EXPECT_FALSE(sparse.dense_eigen);
  EXPECT_TRUE(dense.dense_eigen);
  EXPECT_EQ(sparse.factorization.ordering, "metis");
  // Agreement to 1e-8: the dense solver's own error grows with the condition number of M (tiny
  // rotary inertia beside translational mass); the residual test below bounds Lanczos directly.
  for (int k = 0; k < 12; ++k) EXPECT_NEAR(sparse.lambda[k], dense.lambda[k], 1e-8 * dense.lambda[k]);
  // Spectra's cost: solves per converged mode (printed for the record, bounded loosely).
  std::printf("[ info ] Lanczos: %ld linear solves for 12 modes\n", sparse.eigen_linear_solves);
  EXPECT_LE(sparse.eigen_linear_solves, 12 * 10);
}

TEST(CraigBampton, ReducedFrequenciesConvergeToFullModelAsModesAreAdded) {
  const std::string yaml = test::StraightBeamYaml(kL, 30, kRod, kSteel, "[{name: A}, {name: B}]");
  std::vector<std::vector<double>> errors;
  const int counts[] = {0, 2, 4, 8, 16};
  Eigen::VectorXd full;
  std::printf("[ info ] internal modes | rel. error of free-free flexible modes 1..8 (pairs)\n");
  for (int m : counts) {
    const Superelement se =
        test::Reduce(yaml, {"reduction.internal_modes=" + std::to_string(m), "reduction.full_modes=8"});
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(se.K, se.M);
    full = se.full_free_free_frequencies_hz;
    ASSERT_EQ(full.size(), 14);
    std::vector<double> e;
    std::printf("[ info ] %14d |", m);
    for (int k = 6; k < std::min<int>(14, eig.eigenvalues().size()); ++k) {
      const double f = std::sqrt(eig.eigenvalues()[k]) / (2 * M_PI);
      e.push_back(std::abs(f - full[k]) / full[k]);
      std::printf(" %9.2e", e.back());
    }
    std::printf("\n");
    errors.push_back(e);
  }
  for (size_t i = 1; i < errors.size(); ++i) {
    for (size_t k = 0; k < errors[i].size(); ++k) {
      if (k >= errors[i - 1].size()) continue;  // not present with fewer modes
      EXPECT_LE(errors[i][k], errors[i - 1][k] * (1 + 1e-6) + 1e-12) << "modes " << counts[i] << " k " << k;
    }
  }
  // With 16 modes the first six flexible frequencies are within 1e-3 of the full model and the
  // first four improved tenfold over 4 modes.
  for (int k = 0; k < 6; ++k) EXPECT_LT(errors.back()[k], 1e-3);
  for (int k = 0; k < 4; ++k) EXPECT_LT(errors.back()[k], 0.1 * errors[2][k]);
}

TEST(GeneralizedEigen, LanczosEigenpairsHaveSmallResiduals) {
  PartSpec part = ParsePart(test::StraightBeamYaml(kL, 200, kRod, kSteel, "[{name: A}]"), "t.yaml");
  const FeModel model = BuildBeamModel(part);
  // Clamp interface A: the interior problem of CB.
  std::vector<int> interior = InteriorDofs(model);
  SparseMatrix P(model.n_dofs(), interior.size());
  for (size_t k = 0; k < interior.size(); ++k) P.insert(interior[k], k) = 1.0;
  const SparseMatrix K = P.transpose() * model.K * P, M = P.transpose() * model.M * P;
  SparseCholesky factor;
  ASSERT_TRUE(factor.Compute(K).ok);
  const EigenResult eig = LowestEigenpairs(K, M, 10, 0.0, factor);
  ASSERT_TRUE(eig.ok) << eig.message;
  EXPECT_FALSE(eig.dense);
  // Normwise backward error eta = ||K x - lambda M x|| / ((||K||_1 + |lambda| ||M||_1) ||x||)
  // (Higham): the pair is exact for matrices perturbed by eta relative to their norms.
  auto norm1 = [](const SparseMatrix& A) {
    double best = 0;
    for (int j = 0; j < A.outerSize(); ++j) {
      double sum = 0;
      for (SparseMatrix::InnerIterator it(A, j); it; ++it) sum += std::abs(it.value());
      best = std::max(best, sum);
    }
    return best;
  };
  const double nK = norm1(K), nM = norm1(M);
  for (int k = 0; k < 10; ++k) {
    const Eigen::VectorXd x = eig.vectors.col(k);
    const double eta = (K * x - eig.lambda[k] * (M * x)).norm() / ((nK + eig.lambda[k] * nM) * x.norm());
    EXPECT_LT(eta, 1e-12) << "mode " << k;
    EXPECT_NEAR(x.dot(M * x), 1.0, 1e-10);
  }
}

TEST(CraigBampton, TooManyInternalModesIsAClearFailure) {
  PartSpec part = ParsePart(test::StraightBeamYaml(kL, 2, kRod, kSteel, "[{name: A}, {name: B}]"), "t.yaml");
  const CraigBamptonResult cb = CraigBamptonReduce(BuildBeamModel(part), 50, nullptr);
  EXPECT_FALSE(cb.ok);
  EXPECT_NE(cb.message.find("exceeds the 6 interior DOFs"), std::string::npos) << cb.message;
}

}  // namespace
}  // namespace femb
