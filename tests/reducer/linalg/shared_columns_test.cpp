// K and M shared by columns between MPI ranks (shared_columns.h), on one process: the ranks'
// registry and collectives are stood in for, one rank at a time. Each rank's share of a solid's
// assembly is exactly those columns of the whole; the ranks' parts of a projection and of the
// Green-Lagrange polynomial add up to the whole's (to round-off); the columns gathered from every
// rank are the whole matrix. Meshed once and cut by METIS, each rank holds its part's columns
// (about half) from at most 60% of the elements, and the ranks' K and M are the whole renumbered.
#include "reducer/linalg/shared_columns.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "formats/part_file.h"
#include "reducer/fe/nonlinear_solid.h"
#include "reducer/fe/solid_model.h"
#include "reducer/fe/solid_ranks.h"
#include "reducer/linalg/interior_solver.h"

namespace femb {
namespace {

// This process plays rank `rank` of `ranks`; the sum leaves each rank's part as it is (the test
// adds the parts), the gather returns what `gathered` holds.
class PlayedRanks {
 public:
  PlayedRanks(int ranks, int rank, const std::vector<std::string>* gathered = nullptr) {
    RegisterDistributedSolver(nullptr, ranks, nullptr, rank);
    RegisterRankCollectives(
        [](double*, long) {},
        [gathered](const std::string& mine) { return gathered ? *gathered : std::vector<std::string>{mine}; });
  }
  ~PlayedRanks() {
    RegisterRankCollectives(nullptr, nullptr);
    RegisterDistributedSolver(nullptr, 1);
  }
};

PartSpec Bar() {
  return ParsePart(
      "name: bar\ntype: solid\nmaterial: {E: 2.1e11, nu: 0.3, rho: 7850}\n"
      "geometry: {shape: box, size: [0.4, 0.04, 0.03]}\nmesh: {size: 0.02, order: 2}\n"
      "interfaces: [{name: root, group: xmin}, {name: tip, group: xmax, coupling: rbe3}]\n"
      "reduction: {internal_modes: 4}\n",
      "bar.yaml");
}

TEST(SharedColumns, SharesSplitTheColumnsInRankOrderAsPetscDoes) {
  long next = 0;
  for (int rank = 0; rank < 3; ++rank) {
    PlayedRanks played(3, rank);
    const ColumnShare share = ShareOfColumns(10);
    EXPECT_EQ(share.first, next);
    EXPECT_EQ(share.count, rank == 0 ? 4 : 3);  // 10 = 4 + 3 + 3
    next += share.count;
  }
  EXPECT_EQ(next, 10);
  EXPECT_TRUE(ShareOfColumns(10).whole());  // one process
}

TEST(SharedColumns, EachRankAssemblesExactlyItsColumnsOfTheWholeModel) {
  const PartSpec part = Bar();
  const FeModel whole = BuildSolidModel(part);
  ASSERT_TRUE(whole.columns.whole());
  const auto mesh = std::make_shared<const SolidMesh>(MeshSolidPart(part));
  long entries = 0;
  for (int rank = 0; rank < 2; ++rank) {
    PlayedRanks played(2, rank);
    const FeModel shared = BuildSolidModelOn(part, mesh, true, nullptr, nullptr);
    ASSERT_FALSE(shared.columns.whole());
    EXPECT_EQ(shared.columns.first, rank == 0 ? 0 : ShareOfColumns(whole.n_dofs()).first);
    // The same entries, summed from the same elements in the same order: exactly equal.
    EXPECT_EQ(SparseMatrix(shared.K - KeepColumns(whole.K, shared.columns)).norm(), 0.0);
    EXPECT_EQ(SparseMatrix(shared.M - KeepColumns(whole.M, shared.columns)).norm(), 0.0);
    entries += shared.K.nonZeros();
  }
  EXPECT_EQ(entries, whole.K.nonZeros());
}

TEST(SharedColumns, RanksPartsOfAProjectionAddUpAndGatheredColumnsMakeTheWhole) {
  const FeModel whole = BuildSolidModel(Bar());
  const long n = whole.n_dofs();
  const Eigen::MatrixXd X = Eigen::MatrixXd::Random(n, 5);
  const Eigen::MatrixXd KX = whole.K * X, XKX = X.transpose() * KX;
  const SparseMatrix B = whole.K.topRows(6);  // (a few rows, whole on every rank)
  const Eigen::MatrixXd BX = B * X;
  Eigen::MatrixXd sum_KX = Eigen::MatrixXd::Zero(n, 5), sum_XKX = Eigen::MatrixXd::Zero(5, 5);
  Eigen::MatrixXd sum_BX = Eigen::MatrixXd::Zero(6, 5);
  std::vector<std::string> pieces;
  for (int rank = 0; rank < 2; ++rank) {
    PlayedRanks played(2, rank);
    const ColumnShare share = ShareOfColumns(n);
    const SparseMatrix K_r = KeepColumns(whole.K, share);
    sum_KX += SharedTimes(K_r, X, share);
    // (X^T K X from this rank's rows of X and of K X)
    sum_XKX += TransposeTimesRows(HeldRows(X, share), HeldRows(KX, share), share);
    sum_BX += TimesHeldRows(B, HeldRows(X, share), share);
    std::vector<std::string> mine;
    RegisterRankCollectives([](double*, long) {},
                            [&mine](const std::string& bytes) {
                              mine = {bytes};
                              return mine;
                            });
    GatherColumns(K_r, share);
    pieces.push_back(mine[0]);
  }
  EXPECT_LT((sum_KX - KX).norm(), 1e-13 * KX.norm());
  EXPECT_LT((sum_XKX - XKX).norm(), 1e-13 * XKX.norm());
  EXPECT_LT((sum_BX - BX).norm(), 1e-13 * BX.norm());
  PlayedRanks played(2, 0, &pieces);
  const SparseMatrix gathered = GatherColumns(KeepColumns(whole.K, ShareOfColumns(n)), ShareOfColumns(n));
  EXPECT_EQ(SparseMatrix(gathered - whole.K).norm(), 0.0);
  EXPECT_EQ(gathered.nonZeros(), whole.K.nonZeros());
}

TEST(SharedColumns, RanksSharesOfTheElementsAddUpToTheWholePolynomial) {
  const FeModel model = BuildSolidModel(Bar());
  const SolidType type = *SolidTypeOf(model.cell_type);
  const Eigen::MatrixXd shapes = Eigen::MatrixXd::Random(model.mesh_map.rows(), 4) * 1e-3;
  PolynomialRequest request;
  const ReducedPolynomial whole =
      ReduceSvk(SvkSolidMesh(type, model.nodes, model.cells, Bar().material), shapes, {}, request);
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(4, 4), A = Eigen::MatrixXd::Zero(whole.A.rows(), whole.A.cols()),
                  B = Eigen::MatrixXd::Zero(whole.B.rows(), whole.B.cols());
  Eigen::VectorXd force = Eigen::VectorXd::Zero(model.mesh_map.rows());
  const SvkSolidMesh all(type, model.nodes, model.cells, Bar().material);
  for (int rank = 0; rank < 2; ++rank) {
    PlayedRanks played(2, rank);
    const SvkSolidMesh part(type, model.nodes, model.cells, Bar().material, ShareOfColumns(model.n_elements()));
    const ReducedPolynomial p = ReduceSvk(part, shapes, {}, request);
    K += p.K, A += p.A, B += p.B;
    force += part.Force(shapes.col(0));
  }
  EXPECT_LT((K - whole.K).norm(), 1e-13 * whole.K.norm());
  EXPECT_LT((A - whole.A).norm(), 1e-13 * whole.A.norm());
  EXPECT_LT((B - whole.B).norm(), 1e-13 * whole.B.norm());
  const Eigen::VectorXd f = all.Force(shapes.col(0));
  EXPECT_LT((force - f).norm(), 1e-13 * f.norm());
}

// The model DOF that whole-model DOF i became in a renumbered model: the mesh DOF each free model
// DOF moves (its column of the mesh map holds one entry) is the same; the RBE2 interfaces' six
// each, numbered last in both, and an RBE2 set's DOFs hang on them.
std::vector<long> Renumbering(const SparseMatrix& T_whole, const SparseMatrix& T_new) {
  std::vector<long> model_of_mesh(size_t(T_whole.rows()), -1), renumbered(size_t(T_whole.cols()));
  for (long j = 0; j < T_new.cols(); ++j) {
    renumbered[size_t(j)] = j;  // (the RBE2 interfaces')
    if (T_new.col(j).nonZeros() == 1) model_of_mesh[size_t(SparseMatrix::InnerIterator(T_new, j).row())] = j;
  }
  for (long i = 0; i < T_whole.cols(); ++i)
    if (T_whole.col(i).nonZeros() == 1)
      renumbered[size_t(i)] = model_of_mesh[size_t(SparseMatrix::InnerIterator(T_whole, i).row())];
  return renumbered;
}

TEST(SharedColumns, RankZerosMeshAndMetisPartitionMakeEachRankAssembleAboutItsShare) {
  const PartSpec part = Bar();
  const FeModel whole = BuildSolidModel(part);
  const SolidMesh meshed = MeshSolidPart(part);
  std::vector<long> cells;
  const NodePartition cut = PartitionMesh(meshed, 2, &cells);
  // METIS' parts hold about half the elements each (its default imbalance is 3%).
  ASSERT_EQ(cells.size(), 2u);
  EXPECT_NEAR(double(cells[0]) / double(meshed.cells.rows()), 0.5, 0.03);
  // What rank 0 sends is what the others rebuild.
  NodePartition received;
  const auto mesh = std::make_shared<SolidMesh>(MeshFromBytes(MeshBytes(meshed, cut), &received));
  EXPECT_EQ(received.part, cut.part);
  EXPECT_EQ(received.cell_part, cut.cell_part);
  EXPECT_EQ(received.parts, 2);
  EXPECT_EQ(mesh->nodes, meshed.nodes);
  EXPECT_EQ(mesh->cells, meshed.cells);
  EXPECT_EQ(mesh->node_sets, meshed.node_sets);
  // Each rank holds the columns of its part (numbered part by part), assembled from its part's
  // elements and those touching it: together the whole K and M renumbered, to round-off.
  SparseMatrix K(whole.n_dofs(), whole.n_dofs()), M = K;
  std::vector<long> renumbered;
  long next = 0;
  for (int rank = 0; rank < 2; ++rank) {
    PlayedRanks played(2, rank);
    std::string assembly;
    const FeModel shared = BuildSolidModelOn(part, mesh, true, &received,
                                             [&](const std::string& stage, double, const std::string& detail) {
                                               if (stage == "assembly") assembly = detail;
                                             });
    EXPECT_EQ(shared.columns.first, next);
    // (each rank's element loops take its METIS part's cells)
    EXPECT_EQ(long(shared.rank_cells.size()), cells[size_t(rank)]);
    EXPECT_NEAR(double(shared.columns.count) / double(whole.n_dofs()), 0.5, 0.05);
    next += shared.columns.count;
    const long assembled = std::stol(assembly);  // "N of M elements, ..."
    EXPECT_LT(double(assembled), 0.6 * double(mesh->cells.rows())) << assembly;
    K += shared.K, M += shared.M;
    renumbered = Renumbering(whole.mesh_map, shared.mesh_map);
  }
  EXPECT_EQ(next, whole.n_dofs());
  std::vector<long> seen = renumbered;
  std::sort(seen.begin(), seen.end());
  for (long i = 0; i < whole.n_dofs(); ++i) ASSERT_EQ(seen[size_t(i)], i) << "not a renumbering";
  for (const auto& [A, A_whole] : {std::pair{&K, &whole.K}, std::pair{&M, &whole.M}}) {
    double largest = 0.0, worst = 0.0;
    long entries = 0;
    for (long i = 0; i < A_whole->outerSize(); ++i)
      for (SparseMatrix::InnerIterator it(*A_whole, i); it; ++it, ++entries) {
        largest = std::max(largest, std::abs(it.value()));
        worst = std::max(worst, std::abs(A->coeff(renumbered[size_t(it.row())], renumbered[size_t(i)]) - it.value()));
      }
    EXPECT_EQ(A->nonZeros(), entries);
    EXPECT_LT(worst, 1e-14 * largest);
  }
}

}  // namespace
}  // namespace femb
