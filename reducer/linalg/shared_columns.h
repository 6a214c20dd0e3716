// The model's K and M shared by columns between the MPI ranks of a distributed reduction: each
// rank holds a contiguous range of the columns (its share; the other columns are empty) and
// assembles only the elements that touch it, so their memory divides by the number of ranks.
// Since K and M are symmetric, a rank's columns are also its rows: a product with a replicated
// block is this rank's part of the whole, and the ranks' parts summed (SumOverRanks) make it. The
// reduction's dense blocks are held as each rank's rows while the factor lives (HeldRows,
// SharedTimesRows) and gathered whole after it (GatherRows).
// On one process every function here does nothing more than the plain product: the rank
// collectives are registered by a program that runs on MPI (femb-reduce, mpi_ranks.h).
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "reducer/fe/fe_model.h"

namespace femb {

/// The share of the columns this rank takes of an n-column matrix: n / ranks each, the first
/// n % ranks one more (PETSc's default split), in rank order. The whole on one process.
ColumnShare ShareOfColumns(long n);

/// The collectives of the ranks sharing a reduction: `sum` adds the buffers of all ranks in place,
/// `gather` gives every rank's bytes in rank order, `exchange` sends the bytes of to[r] to rank r
/// and returns what each rank sent this one, in rank order. Each first lets the ranks agree to
/// start (EnsureStartAgreed: it is the ranks' first collective). Unset on one process.
void RegisterRankCollectives(
    std::function<void(double*, long)> sum, std::function<std::vector<std::string>(const std::string&)> gather,
    std::function<std::vector<std::string>(const std::vector<std::string>&)> exchange = nullptr);

/// X computed from this rank's `share` (of a matrix's columns, of the elements): every rank's X
/// added into X, in place, the same on every rank. Nothing when the share is the whole (one
/// process, or a rank that works alone).
void SumOverRanks(Eigen::Ref<Eigen::MatrixXd> X, const ColumnShare& share);

/// The largest of every rank's x, entry by entry, in place (x on one process).
void MaxOverRanks(Eigen::Ref<Eigen::VectorXd> x);

/// Whether `mine` is the same on every rank (true on one process).
bool SameOnRanks(const std::string& mine);

/// Throws RankFailure (exit 3) unless `values` are the same on every rank: the ranks build the
/// model each for itself, and what they replicate (sizes, the mesh, the couplings) must agree.
void CheckSameOnRanks(const std::vector<double>& values, const std::string& what);

/// Rank 0's `bytes` on every rank (what the others pass is not sent): the mesh made once. `bytes`
/// on one process. A failure of rank 0 before it is met here by the others (EnsureStartAgreed).
std::string FromFirstRank(const std::string& bytes);

/// A X for A of which this rank holds the columns `share`: every rank's part summed, the whole
/// product on every rank.
Eigen::MatrixXd SharedTimes(const SparseMatrix& A, const Eigen::MatrixXd& X, const ColumnShare& share);

/// This rank's rows of X: those of the columns `share` holds (the dense blocks of a reduction
/// held as each rank's rows, as the distributed solver gives and takes them). X when the share is
/// the whole.
Eigen::MatrixXd HeldRows(const Eigen::MatrixXd& X, const ColumnShare& share);
/// The same for a sparse A: this rank's rows of it, dense.
Eigen::MatrixXd HeldRows(const SparseMatrix& A, const ColumnShare& share);

/// The whole matrix of which every rank holds its rows (`mine`, its `share`; the ranks' shares
/// follow each other in rank order), on every rank: gathered a few columns at a time. `mine`
/// itself when the share is the whole.
Eigen::MatrixXd GatherRows(const Eigen::MatrixXd& mine, const ColumnShare& share);

/// The rows `wanted` (ascending, of the whole) of X held as each rank's rows (`mine`, its
/// `share`): its own copied, the others' asked of the ranks that hold them (the exchange; without
/// it, gathered whole). X's rows `wanted` when the share is the whole.
Eigen::MatrixXd FetchRows(const Eigen::MatrixXd& mine, const ColumnShare& share, const std::vector<int>& wanted);

/// Every rank's share (first, count), in rank order (on one process: the one share given).
std::vector<ColumnShare> RanksShares(const ColumnShare& share);

/// Blocks of `per_key` rows, one per key (`keys`, ascending; `rows` per_key x keys.size() rows):
/// each sent to the rank owner[i] names and added there to the same key's blocks from the other
/// ranks, after its own, in rank order. Leaves in `keys` and `rows` the keys this rank owns
/// (ascending; also those only other ranks had) and their sums. Needs the exchange collective.
void AddOnOwners(std::vector<int>& keys, Eigen::MatrixXd& rows, int per_key, const std::vector<int>& owner);

/// Blocks of `per_key` rows, one per key (`keys`; each key on one rank), gathered on rank 0 into
/// the whole (per_key n x k, single precision, zero where no rank has the key) a few columns at
/// a time; 0 x k on the other ranks. Needs the exchange collective.
Eigen::MatrixXf GatherBlocksOnFirst(const std::vector<int>& keys, const Eigen::MatrixXd& rows, int per_key, long n);

/// This rank's rows of A X for A shared by columns and X held as its rows (`share` both): each
/// rank's part A_h X_h of the whole, whose rows beyond its own (the layer of the mesh around its
/// part) are sent to the ranks that hold them and added there (without `exchange`: summed over all
/// ranks a few columns at a time). The plain A X when the share is the whole.
Eigen::MatrixXd SharedTimesRows(const SparseMatrix& A, const Eigen::MatrixXd& X, const ColumnShare& share);

/// X^T Y for X and Y held as this rank's rows (`share`): each rank's rows' part, summed (the
/// plain X^T Y, dense_products' TransposeTimes, when the share is the whole).
Eigen::MatrixXd TransposeTimesRows(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y, const ColumnShare& share);

/// X^T A X for A shared by columns and X held as its rows (`share` both): the reduction's
/// projections, X^T (A X) from this rank's rows of A X (SharedTimesRows), summed.
Eigen::MatrixXd RowsCongruence(const SparseMatrix& A, const Eigen::MatrixXd& X, const ColumnShare& share);

/// B X for a few-row B whole on every rank and X held as each rank's rows (`share` of B's
/// columns): each rank's columns of B times its rows, summed. B X when the share is the whole.
Eigen::MatrixXd TimesHeldRows(const SparseMatrix& B, const Eigen::MatrixXd& X, const ColumnShare& share);

/// T times the whole of X held as each rank's rows (`share`), on every rank: X gathered a few
/// columns at a time, each step mapped at once, so that the whole X is never held beside T X
/// (the mode shapes mapped onto the mesh). T X when the share is the whole. `first_only`: on rank
/// 0 only (the file's), 0 x k on the others (without the exchange collective: on every rank).
Eigen::MatrixXd MappedGatherRows(const SparseMatrix& T, const Eigen::MatrixXd& X, const ColumnShare& share,
                                 bool first_only = false);

/// Every rank's entries of A added up (sparse; each rank's A the same size): the whole of a
/// block that the ranks hold pieces of. A itself on one process.
SparseMatrix SumSparseOverRanks(const SparseMatrix& A, const ColumnShare& share);

/// A with only the columns of `share` (the others emptied): the share of a matrix built whole.
SparseMatrix KeepColumns(const SparseMatrix& A, const ColumnShare& share);

/// The whole of A from every rank's columns (`share` this rank's), for the steps that need the
/// full matrix and are only run on small ones: the dense eigen solve of a small interior, the
/// full model's free-free check. A itself on one process.
SparseMatrix GatherColumns(const SparseMatrix& A, const ColumnShare& share);

}  // namespace femb
