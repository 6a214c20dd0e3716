#include "reducer/linalg/shared_columns.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>

#include "reducer/linalg/byte_buffer.h"
#include "reducer/linalg/dense_products.h"
#include "reducer/linalg/interior_solver.h"

namespace femb {
namespace {

struct Collectives {
  std::function<void(double*, long)> sum;
  std::function<std::vector<std::string>(const std::string&)> gather;
  std::function<std::vector<std::string>(const std::vector<std::string>&)> exchange;
};

Collectives& TheCollectives() {
  static Collectives collectives;
  return collectives;
}

}  // namespace

ColumnShare ShareOfColumns(long n) {
  const int ranks = DistributedRanks(), rank = DistributedRank();
  if (ranks <= 1) return {};
  const long base = n / ranks, extra = n % ranks;
  ColumnShare share;
  share.count = base + (rank < extra ? 1 : 0);
  share.first = rank * base + std::min<long>(rank, extra);
  return share;
}

void RegisterRankCollectives(std::function<void(double*, long)> sum,
                             std::function<std::vector<std::string>(const std::string&)> gather,
                             std::function<std::vector<std::string>(const std::vector<std::string>&)> exchange) {
  TheCollectives().sum = std::move(sum);
  TheCollectives().gather = std::move(gather);
  TheCollectives().exchange = std::move(exchange);
}

void SumOverRanks(Eigen::Ref<Eigen::MatrixXd> X, const ColumnShare& share) {
  const Collectives& c = TheCollectives();
  if (share.whole()) return;
  if (!c.sum) throw std::logic_error("a share of a matrix to sum without the ranks' collectives");
  if (X.outerStride() == X.rows()) {
    c.sum(X.data(), long(X.size()));
  } else {
    Eigen::MatrixXd copy = X;
    c.sum(copy.data(), long(copy.size()));
    X = copy;
  }
}

void MaxOverRanks(Eigen::Ref<Eigen::VectorXd> x) {
  const Collectives& c = TheCollectives();
  if (!c.gather) return;
  std::string mine;
  const Eigen::VectorXd copy = x;
  AppendBytes(mine, copy.data(), size_t(copy.size()));
  for (const std::string& bytes : c.gather(mine)) {
    Eigen::VectorXd theirs(x.size());
    TakeBytes(bytes.data(), theirs.data(), size_t(theirs.size()));
    x = x.cwiseMax(theirs);
  }
}

bool SameOnRanks(const std::string& mine) {
  const Collectives& c = TheCollectives();
  if (!c.gather) return true;
  for (const std::string& theirs : c.gather(mine))
    if (theirs != mine) return false;
  return true;
}

void CheckSameOnRanks(const std::vector<double>& values, const std::string& what) {
  if (!SameOnRanks(std::string(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(double)))) {
    throw RankFailure(3,
                      "the MPI ranks built different " + what +
                          " (each rank builds the model itself; a mesher or reader that is not deterministic "
                          "across processes?)",
                      DistributedRank() == 0);
  }
}

std::string FromFirstRank(const std::string& bytes) {
  const Collectives& c = TheCollectives();
  if (!c.gather) return bytes;
  // (the gather with the others' bytes left empty: what every rank receives is rank 0's)
  return c.gather(DistributedRank() == 0 ? bytes : std::string()).front();
}

Eigen::MatrixXd SharedTimes(const SparseMatrix& A, const Eigen::MatrixXd& X, const ColumnShare& share) {
  Eigen::MatrixXd AX = A * X;
  SumOverRanks(AX, share);
  return AX;
}

Eigen::MatrixXd HeldRows(const Eigen::MatrixXd& X, const ColumnShare& share) {
  if (share.whole()) return X;
  return X.middleRows(share.first, share.count);
}

Eigen::MatrixXd HeldRows(const SparseMatrix& A, const ColumnShare& share) {
  if (share.whole()) return Eigen::MatrixXd(A);
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(share.count, A.cols());
  for (int col = 0; col < A.outerSize(); ++col)
    for (SparseMatrix::InnerIterator it(A, col); it; ++it)
      if (share.Holds(it.row())) out(it.row() - share.first, col) = it.value();
  return out;
}

namespace {

// Columns per step of the gathers and products that go a few columns at a time: about 32 MB of
// n-row columns, so that the whole n x k block is never held at once.
long ColumnsPerStep(long n) { return std::max<long>(1, (long(1) << 22) / std::max<long>(n, 1)); }

}  // namespace

Eigen::MatrixXd GatherRows(const Eigen::MatrixXd& mine, const ColumnShare& share) {
  const Collectives& c = TheCollectives();
  if (share.whole() || !c.gather) return mine;
  Eigen::Matrix<double, 1, 1> rows(double(mine.rows()));
  SumOverRanks(rows, share);
  const long n = long(rows(0, 0)), k = mine.cols(), step = ColumnsPerStep(n);
  Eigen::MatrixXd out(n, k);
  for (long c0 = 0; c0 < k; c0 += step) {
    const long w = std::min(step, k - c0);
    std::string bytes;
    AppendBytes(bytes, mine.data() + c0 * mine.rows(), size_t(w * mine.rows()));
    long first = 0;  // (the ranks' rows follow each other in rank order)
    for (const std::string& theirs : c.gather(bytes)) {
      const long count = long(theirs.size() / sizeof(double)) / w;
      const char* at = theirs.data();
      for (long j = 0; j < w && count > 0; ++j) at = TakeBytes(at, &out(first, c0 + j), size_t(count));
      first += count;
    }
  }
  return out;
}

std::vector<ColumnShare> RanksShares(const ColumnShare& share) {
  if (!TheCollectives().gather) return {share};
  std::string mine;
  const long header[2] = {share.first, share.count};
  AppendBytes(mine, header, 2);
  std::vector<ColumnShare> shares;
  for (const std::string& bytes : TheCollectives().gather(mine)) {
    long h[2];
    TakeBytes(bytes.data(), h, 2);
    shares.push_back({h[0], h[1]});
  }
  return shares;
}

namespace {

// The entries of `sorted` (ascending) in each rank's share: [begin, end) per rank.
std::vector<std::pair<long, long>> RanksEntries(const std::vector<int>& sorted,
                                                const std::vector<ColumnShare>& shares) {
  std::vector<std::pair<long, long>> ranges;
  for (const ColumnShare& s : shares) {
    const long begin = std::lower_bound(sorted.begin(), sorted.end(), int(s.first)) - sorted.begin();
    const long end =
        std::lower_bound(sorted.begin(), sorted.end(), int(s.first + std::max<long>(s.count, 0))) - sorted.begin();
    ranges.emplace_back(begin, end);
  }
  return ranges;
}

// SharedTimesRows by the exchange: this rank's part A_h X_h on its own rows and on the rows
// beyond them that its columns touch (`ghosts`, ascending); those go to the ranks that hold them
// (each rank's in one message: row indices, then the rows' values), which add them in rank order.
Eigen::MatrixXd TimesRowsExchanged(const SparseMatrix& A, const Eigen::MatrixXd& X, const ColumnShare& share) {
  const long first = share.first, count = share.count, k = X.cols();
  std::vector<int> ghosts;
  for (long col = first; col < first + count; ++col)
    for (SparseMatrix::InnerIterator it(A, Eigen::Index(col)); it; ++it)
      if (!share.Holds(it.row())) ghosts.push_back(int(it.row()));
  std::sort(ghosts.begin(), ghosts.end());
  ghosts.erase(std::unique(ghosts.begin(), ghosts.end()), ghosts.end());
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(count, k), G = Eigen::MatrixXd::Zero(long(ghosts.size()), k);
  for (long c = 0; c < k; ++c)
    for (long col = first; col < first + count; ++col) {
      const double x = X(col - first, c);
      for (SparseMatrix::InnerIterator it(A, Eigen::Index(col)); it; ++it) {
        if (share.Holds(it.row())) {
          out(it.row() - first, c) += it.value() * x;
        } else {
          const long g = std::lower_bound(ghosts.begin(), ghosts.end(), int(it.row())) - ghosts.begin();
          G(g, c) += it.value() * x;
        }
      }
    }
  // (the ghost rows to the ranks that hold them, added there)
  const std::vector<ColumnShare> shares = RanksShares(share);
  const std::vector<std::pair<long, long>> held = RanksEntries(ghosts, shares);
  std::vector<int> owner(ghosts.size());
  for (size_t r = 0; r < held.size(); ++r)
    std::fill(owner.begin() + held[r].first, owner.begin() + held[r].second, int(r));
  AddOnOwners(ghosts, G, 1, owner);
  for (size_t i = 0; i < ghosts.size(); ++i) out.row(ghosts[i] - first) += G.row(long(i));
  return out;
}

}  // namespace

Eigen::MatrixXd FetchRows(const Eigen::MatrixXd& mine, const ColumnShare& share, const std::vector<int>& wanted) {
  const long k = mine.cols();
  Eigen::MatrixXd out(long(wanted.size()), k);
  if (share.whole() || !TheCollectives().exchange) {
    const Eigen::MatrixXd whole = GatherRows(mine, share);
    for (size_t i = 0; i < wanted.size(); ++i) out.row(long(i)) = whole.row(wanted[i]);
    return out;
  }
  const std::vector<ColumnShare> shares = RanksShares(share);
  const std::vector<std::pair<long, long>> asked = RanksEntries(wanted, shares);
  // Its own rows copied; the rows asked of each other rank, then its answer: the rows' values,
  // column-major.
  const size_t me = size_t(DistributedRank());
  for (long i = asked[me].first; i < asked[me].second; ++i) out.row(i) = mine.row(wanted[size_t(i)] - share.first);
  std::vector<std::string> questions(shares.size());
  for (size_t r = 0; r < shares.size(); ++r)
    if (r != me) AppendBytes(questions[r], wanted.data() + asked[r].first, size_t(asked[r].second - asked[r].first));
  const std::vector<std::string> theirs = TheCollectives().exchange(questions);
  std::vector<std::string> answers(shares.size());
  for (size_t r = 0; r < shares.size(); ++r) {
    std::vector<int> rows(theirs[r].size() / sizeof(int));
    TakeBytes(theirs[r].data(), rows.data(), rows.size());
    Eigen::MatrixXd values(long(rows.size()), k);
    for (size_t i = 0; i < rows.size(); ++i) values.row(long(i)) = mine.row(rows[i] - share.first);
    AppendBytes(answers[r], values.data(), size_t(values.size()));
  }
  const std::vector<std::string> received = TheCollectives().exchange(answers);
  for (size_t r = 0; r < shares.size(); ++r) {
    const long rows = asked[r].second - asked[r].first;
    if (rows == 0 || r == me) continue;  // (Eigen's slice assignment of no rows can read before them)
    Eigen::MatrixXd values(rows, k);
    TakeBytes(received[r].data(), values.data(), size_t(values.size()));
    out.middleRows(asked[r].first, rows) = values;
  }
  return out;
}

Eigen::MatrixXd SharedTimesRows(const SparseMatrix& A, const Eigen::MatrixXd& X, const ColumnShare& share) {
  if (share.whole()) return A * X;
  if (TheCollectives().exchange) return TimesRowsExchanged(A, X, share);
  const long k = X.cols(), step = ColumnsPerStep(A.rows());
  Eigen::MatrixXd out(share.count, k);
  for (long c0 = 0; c0 < k; c0 += step) {
    const long w = std::min(step, k - c0);
    // (A's other columns are empty: its held columns times this rank's rows of X is its part)
    Eigen::MatrixXd part = A.middleCols(share.first, share.count) * X.middleCols(c0, w);
    SumOverRanks(part, share);
    out.middleCols(c0, w) = part.middleRows(share.first, share.count);
  }
  return out;
}

Eigen::MatrixXd TransposeTimesRows(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y, const ColumnShare& share) {
  Eigen::MatrixXd XtY = TransposeTimes(X, Y);
  SumOverRanks(XtY, share);
  return XtY;
}

Eigen::MatrixXd RowsCongruence(const SparseMatrix& A, const Eigen::MatrixXd& X, const ColumnShare& share) {
  const Eigen::MatrixXd AX = SharedTimesRows(A, X, share);
  return TransposeTimesRows(X, AX, share);
}

Eigen::MatrixXd TimesHeldRows(const SparseMatrix& B, const Eigen::MatrixXd& X, const ColumnShare& share) {
  if (share.whole()) return B * X;
  Eigen::MatrixXd BX = B.middleCols(share.first, share.count) * X;
  SumOverRanks(BX, share);
  return BX;
}

namespace {

// The whole of X held as each rank's rows (`share`) on rank 0 (the ranks' rows in rank order),
// 0 x k on the others.
Eigen::MatrixXd GatherRowsOnFirst(const Eigen::MatrixXd& mine) {
  const long k = mine.cols();
  std::vector<std::string> to(static_cast<size_t>(DistributedRanks()));
  AppendBytes(to[0], mine.data(), size_t(mine.size()));
  const std::vector<std::string> received = TheCollectives().exchange(to);
  if (DistributedRank() != 0) return Eigen::MatrixXd(0, k);
  std::vector<long> counts;
  for (const std::string& bytes : received) counts.push_back(k > 0 ? long(bytes.size() / sizeof(double)) / k : 0);
  Eigen::MatrixXd out(std::accumulate(counts.begin(), counts.end(), 0L), k);
  long first = 0;
  for (size_t r = 0; r < received.size(); ++r) {
    const char* at = received[r].data();
    for (long j = 0; j < k && counts[r] > 0; ++j) at = TakeBytes(at, &out(first, j), size_t(counts[r]));
    first += counts[r];
  }
  return out;
}

}  // namespace

Eigen::MatrixXd MappedGatherRows(const SparseMatrix& T, const Eigen::MatrixXd& X, const ColumnShare& share,
                                 bool first_only) {
  if (share.whole()) return T * X;
  first_only = first_only && TheCollectives().exchange;
  Eigen::Matrix<double, 1, 1> rows(double(X.rows()));
  SumOverRanks(rows, share);
  const long k = X.cols(), step = ColumnsPerStep(long(rows(0, 0)));
  const bool here = !first_only || DistributedRank() == 0;
  Eigen::MatrixXd TX(here ? T.rows() : 0, k);
  for (long c0 = 0; c0 < k; c0 += step) {
    const long w = std::min(step, k - c0);
    const Eigen::MatrixXd columns = X.middleCols(c0, w);
    const Eigen::MatrixXd whole = first_only ? GatherRowsOnFirst(columns) : GatherRows(columns, share);
    if (here) TX.middleCols(c0, w) = T * whole;
  }
  return TX;
}

void AddOnOwners(std::vector<int>& keys, Eigen::MatrixXd& rows, int per_key, const std::vector<int>& owner) {
  const int me = DistributedRank();
  const long k = rows.cols();
  std::vector<std::vector<long>> to_rank(static_cast<size_t>(DistributedRanks()));
  std::vector<long> kept;
  for (size_t i = 0; i < keys.size(); ++i) (owner[i] == me ? kept : to_rank[size_t(owner[i])]).push_back(long(i));
  // To each rank: the count, its keys, then their blocks (column-major).
  std::vector<std::string> to(to_rank.size());
  for (size_t r = 0; r < to_rank.size(); ++r) {
    const long count = long(to_rank[r].size());
    if (count == 0) continue;
    std::vector<int> sent_keys;
    Eigen::MatrixXd blocks(per_key * count, k);
    for (long j = 0; j < count; ++j) {
      sent_keys.push_back(keys[size_t(to_rank[r][size_t(j)])]);
      blocks.middleRows(per_key * j, per_key) = rows.middleRows(per_key * to_rank[r][size_t(j)], per_key);
    }
    AppendBytes(to[r], &count, 1);
    AppendBytes(to[r], sent_keys.data(), sent_keys.size());
    AppendBytes(to[r], blocks.data(), size_t(blocks.size()));
  }
  const std::vector<std::string> received = TheCollectives().exchange(to);
  std::vector<int> owned;
  for (const long i : kept) owned.push_back(keys[size_t(i)]);
  std::vector<std::pair<std::vector<int>, Eigen::MatrixXd>> theirs;
  for (const std::string& bytes : received) {
    if (bytes.empty()) continue;
    long count = 0;
    const char* at = TakeBytes(bytes.data(), &count, 1);
    std::vector<int> their_keys(static_cast<size_t>(count));
    at = TakeBytes(at, their_keys.data(), their_keys.size());
    Eigen::MatrixXd blocks(per_key * count, k);
    TakeBytes(at, blocks.data(), size_t(blocks.size()));
    owned.insert(owned.end(), their_keys.begin(), their_keys.end());
    theirs.emplace_back(std::move(their_keys), std::move(blocks));
  }
  std::sort(owned.begin(), owned.end());
  owned.erase(std::unique(owned.begin(), owned.end()), owned.end());
  const auto at_key = [&owned](int key) {
    return long(std::lower_bound(owned.begin(), owned.end(), key) - owned.begin());
  };
  Eigen::MatrixXd sums = Eigen::MatrixXd::Zero(per_key * long(owned.size()), k);
  for (const long i : kept)
    sums.middleRows(per_key * at_key(keys[size_t(i)]), per_key) += rows.middleRows(per_key * i, per_key);
  for (const auto& [their_keys, blocks] : theirs)
    for (size_t j = 0; j < their_keys.size(); ++j)
      sums.middleRows(per_key * at_key(their_keys[j]), per_key) += blocks.middleRows(per_key * long(j), per_key);
  keys = std::move(owned);
  rows = std::move(sums);
}

Eigen::MatrixXf GatherBlocksOnFirst(const std::vector<int>& keys, const Eigen::MatrixXd& rows, int per_key, long n) {
  const bool first = DistributedRank() == 0;
  const long k = rows.cols(), step = ColumnsPerStep(per_key * n);
  Eigen::MatrixXf whole = first ? Eigen::MatrixXf::Zero(per_key * n, k) : Eigen::MatrixXf(0, k);
  const std::vector<int> to_first(keys.size(), 0);
  for (long c0 = 0; c0 < k; c0 += step) {
    // (every block owned by rank 0: each key is on one rank, so its sum is its block)
    const long w = std::min(step, k - c0);
    std::vector<int> gathered = keys;
    Eigen::MatrixXd blocks = rows.middleCols(c0, w);
    AddOnOwners(gathered, blocks, per_key, to_first);
    for (size_t j = 0; j < gathered.size(); ++j)
      whole.block(per_key * long(gathered[j]), c0, per_key, w) =
          blocks.middleRows(per_key * long(j), per_key).cast<float>();
  }
  return whole;
}

SparseMatrix SumSparseOverRanks(const SparseMatrix& A, const ColumnShare& share) {
  const Collectives& c = TheCollectives();
  if (share.whole() || !c.gather) return A;
  std::vector<int> rows, cols;
  std::vector<double> values;
  for (int col = 0; col < A.outerSize(); ++col)
    for (SparseMatrix::InnerIterator it(A, col); it; ++it) {
      rows.push_back(int(it.row()));
      cols.push_back(col);
      values.push_back(it.value());
    }
  std::string mine;
  const long entries = long(rows.size());
  AppendBytes(mine, &entries, 1);
  AppendBytes(mine, rows.data(), rows.size());
  AppendBytes(mine, cols.data(), cols.size());
  AppendBytes(mine, values.data(), values.size());
  std::vector<Eigen::Triplet<double>> triplets;
  for (const std::string& bytes : c.gather(mine)) {
    long k = 0;
    const char* at = TakeBytes(bytes.data(), &k, 1);
    std::vector<int> r(static_cast<size_t>(k)), q(static_cast<size_t>(k));
    std::vector<double> v(static_cast<size_t>(k));
    at = TakeBytes(at, r.data(), r.size());
    at = TakeBytes(at, q.data(), q.size());
    TakeBytes(at, v.data(), v.size());
    for (size_t e = 0; e < r.size(); ++e) triplets.emplace_back(r[e], q[e], v[e]);
  }
  SparseMatrix out(A.rows(), A.cols());
  out.setFromTriplets(triplets.begin(), triplets.end());
  return out;
}

SparseMatrix KeepColumns(const SparseMatrix& A, const ColumnShare& share) {
  if (share.whole()) return A;
  const long n = A.cols(), first = share.first, last = share.end(n);
  SparseMatrix out(A.rows(), n);
  long entries = 0;
  for (long c = first; c < last; ++c) entries += A.outerIndexPtr()[c + 1] - A.outerIndexPtr()[c];
  out.reserve(entries);
  for (long c = 0; c < n; ++c) {
    out.startVec(Eigen::Index(c));
    if (c < first || c >= last) continue;
    for (SparseMatrix::InnerIterator it(A, Eigen::Index(c)); it; ++it) out.insertBack(it.row(), it.col()) = it.value();
  }
  out.finalize();
  return out;
}

SparseMatrix GatherColumns(const SparseMatrix& A, const ColumnShare& share) {
  // (the other ranks' columns are empty here: each entry comes from the one rank that holds it)
  return SumSparseOverRanks(A, share);
}

}  // namespace femb
