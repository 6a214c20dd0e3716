// The dense blocks of a reduction held as each MPI rank's rows (shared_columns.h), on real ranks
// (mpirun -np 3: MpiRanks registers MPI's collectives): gathered rows are the whole block exactly,
// whatever the column count (several gather steps, no columns, a rank without rows); this rank's
// rows of A X from A's share of columns and X's share of rows, the rows its columns touch beyond
// its own sent to the ranks that hold them, are those of the whole product (1e-14 of its norm:
// only the order of the sums differs), and so are the projection X^T A X from the rows and a map
// of the gathered rows (on every rank, or on rank 0 only); rows fetched from the ranks that hold
// them are the block's exactly; blocks keyed by node add up exactly on their owners and gather on
// rank 0 (zero where no rank had one); the ranks' pieces of a sparse block add up to it exactly.
// Each rank builds the same matrices from one seed.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "reducer/distributed/mpi_ranks.h"
#include "reducer/linalg/interior_solver.h"
#include "reducer/linalg/shared_columns.h"

namespace femb {
namespace {

// A symmetric banded n x n matrix with random entries, the same on every rank.
SparseMatrix Banded(long n, int half_width, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  std::vector<Eigen::Triplet<double>> entries;
  for (long j = 0; j < n; ++j) {
    entries.emplace_back(int(j), int(j), 4.0 + value(random));
    for (long i = j + 1; i <= std::min(n - 1, j + half_width); ++i) {
      const double v = value(random);
      entries.emplace_back(int(i), int(j), v);
      entries.emplace_back(int(j), int(i), v);
    }
  }
  SparseMatrix A(n, n);
  A.setFromTriplets(entries.begin(), entries.end());
  return A;
}

Eigen::MatrixXd RandomBlock(long n, long k, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  Eigen::MatrixXd X(n, k);
  for (long c = 0; c < k; ++c)
    for (long i = 0; i < n; ++i) X(i, c) = value(random);
  return X;
}

TEST(RankRows, GatheredRowsAreTheWholeBlockExactly) {
  ASSERT_GT(DistributedRanks(), 1);
  // 2^16 rows: 64 columns per gather step, so 70 columns take two; 2 rows: a rank holds none.
  for (const long n : {long(1) << 16, 1000L, 2L}) {
    const ColumnShare share = ShareOfColumns(n);
    ASSERT_FALSE(share.whole());
    for (const long k : {70L, 1L, 0L}) {
      if (n == (long(1) << 16) && k != 70) continue;
      const Eigen::MatrixXd X = RandomBlock(n, k, 7);
      const Eigen::MatrixXd mine = HeldRows(X, share);
      EXPECT_EQ(mine.rows(), share.count);
      const Eigen::MatrixXd gathered = GatherRows(mine, share);
      ASSERT_EQ(gathered.rows(), n);
      ASSERT_EQ(gathered.cols(), k);
      EXPECT_TRUE(gathered == X) << n << " x " << k;
    }
  }
}

TEST(RankRows, RowsOfAProductFromSharedColumnsAreThoseOfTheWhole) {
  for (const long n : {long(1) << 16, 1000L}) {
    const SparseMatrix A = Banded(n, 5, 11);
    const Eigen::MatrixXd X = RandomBlock(n, n > 1000 ? 70 : 9, 13);
    const ColumnShare share = ShareOfColumns(n);
    const Eigen::MatrixXd whole = A * X;
    const Eigen::MatrixXd mine = SharedTimesRows(KeepColumns(A, share), HeldRows(X, share), share);
    const Eigen::MatrixXd expected = HeldRows(whole, share);
    ASSERT_EQ(mine.rows(), expected.rows());
    ASSERT_EQ(mine.cols(), expected.cols());
    EXPECT_LE((mine - expected).norm(), 1e-14 * whole.norm()) << n;
    // The projection X^T A X from the ranks' rows, and T X gathered mapped a few columns at a
    // time (T: a sparse map onto more rows than X has), the same on every rank.
    const Eigen::MatrixXd XAX = X.transpose() * whole;
    const Eigen::MatrixXd projected = RowsCongruence(KeepColumns(A, share), HeldRows(X, share), share);
    EXPECT_LE((projected - XAX).norm(), 1e-14 * XAX.norm()) << n;
    const SparseMatrix T = SparseMatrix(Banded(n + 7, 2, 19).leftCols(n));
    const Eigen::MatrixXd TX = T * X;
    const Eigen::MatrixXd mapped = MappedGatherRows(T, HeldRows(X, share), share);
    ASSERT_EQ(mapped.rows(), n + 7);
    EXPECT_LE((mapped - TX).norm(), 1e-14 * TX.norm()) << n;
  }
}

TEST(RankRows, FetchedRowsAreTheWholeBlocksRowsExactly) {
  const long n = 1000;
  const ColumnShare share = ShareOfColumns(n);
  const Eigen::MatrixXd X = RandomBlock(n, 7, 23);
  const Eigen::MatrixXd mine = HeldRows(X, share);
  // Each rank asks for a different set: every third row from its rank on (rows of every rank),
  // the first rank's rows only, and none.
  std::vector<std::vector<int>> asks(3);
  for (long i = DistributedRank(); i < n; i += 3) asks[0].push_back(int(i));
  for (long i = 0; i < ShareOfColumns(n).count && DistributedRank() == 2; ++i) asks[1].push_back(int(i));
  for (const std::vector<int>& wanted : asks) {
    const Eigen::MatrixXd rows = FetchRows(mine, share, wanted);
    ASSERT_EQ(rows.rows(), long(wanted.size()));
    ASSERT_EQ(rows.cols(), X.cols());
    for (size_t i = 0; i < wanted.size(); ++i) ASSERT_TRUE(rows.row(long(i)) == X.row(wanted[i])) << wanted[i];
  }
}

// Rank r's value of row i of key's block, column j (whole numbers: their sums are exact).
double BlockValue(int key, long i, long j, int rank) {
  return 1000.0 * rank + 10.0 * key + 3.0 * double(i) + double(j);
}

TEST(RankRows, KeyedBlocksAddOnTheirOwnersAndGatherOnTheFirstRank) {
  const int ranks = DistributedRanks(), rank = DistributedRank(), per_key = 2;
  const long n = 40, k = 3;
  // Rank r has the keys with key % (r + 2) == 0 (keys on several ranks, and on none: 1, 5, 7,
  // ...); key's owner is key % ranks.
  const auto has = [](int key, int r) { return key % (r + 2) == 0; };
  std::vector<int> keys, owner;
  for (int key = 0; key < n; ++key)
    if (has(key, rank)) keys.push_back(key), owner.push_back(key % ranks);
  Eigen::MatrixXd rows(per_key * long(keys.size()), k);
  for (size_t b = 0; b < keys.size(); ++b)
    for (long i = 0; i < per_key; ++i)
      for (long j = 0; j < k; ++j) rows(per_key * long(b) + i, j) = BlockValue(keys[b], i, j, rank);
  AddOnOwners(keys, rows, per_key, owner);
  std::vector<int> expected_keys;
  Eigen::MatrixXd expected = Eigen::MatrixXd::Zero(per_key * n, k);
  for (int key = 0; key < n; ++key)
    for (int r = 0; r < ranks; ++r) {
      if (!has(key, r)) continue;
      if (key % ranks == rank && (expected_keys.empty() || expected_keys.back() != key)) expected_keys.push_back(key);
      for (long i = 0; i < per_key; ++i)
        for (long j = 0; j < k; ++j) expected(per_key * key + i, j) += BlockValue(key, i, j, r);
    }
  ASSERT_EQ(keys, expected_keys);
  for (size_t b = 0; b < keys.size(); ++b)
    EXPECT_TRUE(rows.middleRows(per_key * long(b), per_key) == expected.middleRows(per_key * keys[b], per_key));
  const Eigen::MatrixXf whole = GatherBlocksOnFirst(keys, rows, per_key, n);
  if (rank == 0) {
    EXPECT_TRUE(whole == expected.cast<float>());  // (zero where no rank had the key)
  } else {
    EXPECT_EQ(whole.rows(), 0);
  }
  // The shapes on the mesh on rank 0 only: the whole T X there, no rows elsewhere.
  const ColumnShare share = ShareOfColumns(n);
  const Eigen::MatrixXd X = RandomBlock(n, k, 29);
  const SparseMatrix T = SparseMatrix(Banded(n + 5, 1, 31).leftCols(n));
  const Eigen::MatrixXd mapped = MappedGatherRows(T, HeldRows(X, share), share, true);
  EXPECT_EQ(mapped.rows(), rank == 0 ? n + 5 : 0);
  if (rank == 0) EXPECT_LE((mapped - T * X).norm(), 1e-14 * (T * X).norm());
}

TEST(RankRows, RanksPiecesOfASparseBlockAddUpToItExactly) {
  const long n = 500;
  const SparseMatrix A = Banded(n, 3, 17);
  const int ranks = DistributedRanks(), rank = DistributedRank();
  std::vector<Eigen::Triplet<double>> mine;
  for (int col = 0; col < A.outerSize(); ++col)
    for (SparseMatrix::InnerIterator it(A, col); it; ++it)
      if ((it.row() + col) % ranks == rank) mine.emplace_back(int(it.row()), col, it.value());
  SparseMatrix piece(n, n);
  piece.setFromTriplets(mine.begin(), mine.end());
  const SparseMatrix summed = SumSparseOverRanks(piece, ShareOfColumns(n));
  EXPECT_EQ(summed.nonZeros(), A.nonZeros());
  EXPECT_EQ(SparseMatrix(summed - A).norm(), 0.0);
}

}  // namespace
}  // namespace femb

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  const femb::MpiRanks ranks;
  if (ranks.rank() != 0) {  // (one report: rank 0's; every rank's exit code counts)
    ::testing::TestEventListeners& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
  }
  return RUN_ALL_TESTS();
}
