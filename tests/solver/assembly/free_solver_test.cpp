// FreeSolver (solver/assembly/system.h): KLU on the coordinates solved for, the analysis kept
// per pattern, the pivot order reused while its pivots stay good. Reference: a dense LU of the
// same free block (Eigen's PartialPivLU), residuals to round-off.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "solver/assembly/system.h"

namespace femb {
namespace {

// A model of `nodes` nodes: node 0 on a driven revolute joint to ground (its one coordinate
// prescribed: not solved for), the others free (6 coordinates each).
SystemModel Nodes(int nodes) {
  SystemModel model;
  for (int k = 0; k < nodes; ++k) AddNode(model, "n" + std::to_string(k), Eigen::Vector3d(k, 0, 0));
  RevoluteToGround(model, 0, Eigen::Vector3d::UnitZ());
  SystemModel::Prescribed drive;
  drive.node = 0;
  drive.value = drive.rate = drive.acceleration = [](double) { return 0.0; };
  model.prescribed.push_back(drive);
  model.Number();
  return model;
}

// A banded nonsymmetric matrix over all coordinates (a chain of bodies), diagonally weighted by
// `diagonal`, entries drawn from `seed`.
SystemMatrix Banded(int n, double diagonal, unsigned seed, int band = 8) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Triplets t;
  for (int i = 0; i < n; ++i)
    for (int j = std::max(0, i - band); j < std::min(n, i + band + 1); ++j)
      t.emplace_back(i, j, i == j ? diagonal + u(rng) : u(rng));
  return ToMatrix(n, t);
}

// || S_ff x_f - r_f || / || r_f || on the free coordinates, and x zero on the others.
double RelativeResidual(const DofMap& dofs, const SystemMatrix& S, const Eigen::VectorXd& x, const Eigen::VectorXd& r) {
  const Eigen::VectorXd Sx = S * x;
  double num = 0.0, den = 0.0;
  for (int j : dofs.solved()) {
    num += (Sx[j] - r[j]) * (Sx[j] - r[j]);
    den += r[j] * r[j];
  }
  return std::sqrt(num / den);
}

TEST(FreeSolver, SolvesOnTheFreeCoordinatesLikeADenseLU) {
  const SystemModel model = Nodes(20);
  const DofMap dofs(model);
  const int n = dofs.n_dofs();
  ASSERT_EQ(int(dofs.solved().size()), n - 1);  // the driven joint's coordinate is not solved for
  const SystemMatrix S = Banded(n, 4.0, 1);
  const Eigen::VectorXd r = Eigen::VectorXd::LinSpaced(n, -1.0, 2.0);
  FreeSolver solver;
  ASSERT_TRUE(solver.Factor(dofs, S));
  const Eigen::VectorXd x = solver.Solve(r);
  EXPECT_LT(RelativeResidual(dofs, S, x, r), 1e-13);
  // The dense reference on the free block.
  const Eigen::MatrixXd A = DenseFreeMatrix(dofs, S);
  Eigen::VectorXd rf(dofs.solved().size());
  for (size_t i = 0; i < dofs.solved().size(); ++i) rf[Eigen::Index(i)] = r[dofs.solved()[i]];
  const Eigen::VectorXd xf = A.partialPivLu().solve(rf);
  for (size_t i = 0; i < dofs.solved().size(); ++i)
    EXPECT_NEAR(x[dofs.solved()[i]], xf[Eigen::Index(i)], 1e-12 * xf.norm());
  for (int j = 0; j < n; ++j) {
    if (dofs.prescribed(j)) {
      EXPECT_EQ(x[j], 0.0);
    }
  }
}

// Newton's iteration matrices change values, not pattern: the second factorization reuses the
// pivot order (counted), and its solution is as accurate as a fresh factorization's.
TEST(FreeSolver, ReusesThePivotOrderForNewValuesOfThePattern) {
  const SystemModel model = Nodes(30);
  const DofMap dofs(model);
  const int n = dofs.n_dofs();
  FreeSolver solver;
  const Eigen::VectorXd r = Eigen::VectorXd::Ones(n);
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const SystemMatrix S = Banded(n, 6.0 + seed, seed);
    ASSERT_TRUE(solver.Factor(dofs, S));
    EXPECT_LT(RelativeResidual(dofs, S, solver.Solve(r), r), 1e-13) << "seed " << seed;
  }
  EXPECT_EQ(solver.full_factorizations(), 1);
  EXPECT_EQ(solver.refactorizations(), 4);
}

// A matrix whose kept pivot order meets a zero pivot (the diagonal entry the first
// factorization pivoted on vanishes): Factor pivots anew and stays exact.
TEST(FreeSolver, PivotsAnewWhenTheKeptOrderFails) {
  SystemModel model = Nodes(2);
  const DofMap dofs(model);
  const int n = dofs.n_dofs();
  auto build = [&](double d) {
    Triplets t;
    for (int i = 0; i < n; ++i) t.emplace_back(i, i, i == 3 ? d : 2.0 + i);
    t.emplace_back(3, 4, 1.0);
    t.emplace_back(4, 3, 1.0);
    return ToMatrix(n, t);
  };
  FreeSolver solver;
  const Eigen::VectorXd r = Eigen::VectorXd::LinSpaced(n, 1.0, 2.0);
  ASSERT_TRUE(solver.Factor(dofs, build(5.0)));
  const SystemMatrix S = build(0.0);  // zero where the first factorization had a pivot
  ASSERT_TRUE(solver.Factor(dofs, S));
  EXPECT_LT(RelativeResidual(dofs, S, solver.Solve(r), r), 1e-14);
  EXPECT_EQ(solver.full_factorizations(), 2);
}

// A new pattern (the model's structure changed) is analysed anew; a structurally singular
// matrix (an empty column) is refused, and so is one with a non-finite entry.
TEST(FreeSolver, NewPatternsAndSingularMatrices) {
  const SystemModel model = Nodes(10);
  const DofMap dofs(model);
  const int n = dofs.n_dofs();
  FreeSolver solver;
  const Eigen::VectorXd r = Eigen::VectorXd::Ones(n);
  ASSERT_TRUE(solver.Factor(dofs, Banded(n, 5.0, 3, 4)));
  const SystemMatrix wider = Banded(n, 5.0, 4, 9);
  ASSERT_TRUE(solver.Factor(dofs, wider));
  EXPECT_LT(RelativeResidual(dofs, wider, solver.Solve(r), r), 1e-13);
  EXPECT_EQ(solver.full_factorizations(), 2);
  Triplets t;
  for (int i = 0; i < n; ++i)
    if (i != 20) t.emplace_back(i, i, 1.0);  // coordinate 20: an empty row and column
  EXPECT_FALSE(solver.Factor(dofs, ToMatrix(n, t)));
  EXPECT_FALSE(solver.valid());
  SystemMatrix bad = Banded(n, 5.0, 3, 4);
  bad.coeffRef(12, 12) = std::nan("");
  EXPECT_FALSE(solver.Factor(dofs, bad));
}

// TripletAssembler: the same sequence of rows and columns with new values gives the matrix
// setFromTriplets gives, to the bit (duplicates summed in triplet order), without a rebuild; a
// different sequence rebuilds.
TEST(TripletAssembler, ReusesTheSlotsOfARepeatedSequence) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> index(0, 29);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  Triplets t;
  for (int i = 0; i < 400; ++i) t.emplace_back(index(rng), index(rng), value(rng));  // many duplicates
  TripletAssembler assembler;
  for (int round = 0; round < 3; ++round) {
    for (auto& e : t) e = Eigen::Triplet<double>(e.row(), e.col(), value(rng));
    const SystemMatrix expected = ToMatrix(30, t);
    const SystemMatrix& built = assembler.Build(30, t);
    ASSERT_EQ(built.nonZeros(), expected.nonZeros());
    EXPECT_EQ((Eigen::MatrixXd(built) - Eigen::MatrixXd(expected)).cwiseAbs().maxCoeff(), 0.0) << "round " << round;
  }
  EXPECT_EQ(assembler.rebuilds(), 1);
  t.emplace_back(3, 4, 1.0);
  EXPECT_EQ((Eigen::MatrixXd(assembler.Build(30, t)) - Eigen::MatrixXd(ToMatrix(30, t))).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(assembler.rebuilds(), 2);
}

}  // namespace
}  // namespace femb
