#include "reducer/reduction/interior_blocks.h"

namespace femb {

Blocks Partition(const SparseMatrix& A, const std::vector<int>& interior_index, const std::vector<int>& boundary_index,
                 int n_i, int n_b) {
  // Interior and boundary indices keep the order of A, so each block fills column by column
  // with rows ascending: built in place, no triplet list (A may hold 1e8 entries).
  Blocks out;
  out.ii.resize(n_i, n_i);
  out.ib.resize(n_i, n_b);
  out.ii.reserve(A.nonZeros());
  std::vector<std::vector<std::pair<int, double>>> ib_cols(n_b);
  for (int col = 0; col < A.outerSize(); ++col) {
    const int ci = interior_index[col], cb = boundary_index[col];
    if (ci >= 0) out.ii.startVec(ci);
    for (SparseMatrix::InnerIterator it(A, col); it; ++it) {
      const int ri = interior_index[it.row()];
      if (ri < 0 || ci < 0) out.rest.emplace_back(int(it.row()), col, it.value());
      if (ri >= 0 && ci >= 0) {
        out.ii.insertBack(ri, ci) = it.value();
      } else if (ri >= 0 && cb >= 0) {
        ib_cols[cb].emplace_back(ri, it.value());
      }
    }
  }
  out.ii.finalize();
  out.ii.makeCompressed();
  std::size_t n_ib = 0;
  for (const auto& c : ib_cols) n_ib += c.size();
  out.ib.reserve(long(n_ib));
  for (int c = 0; c < n_b; ++c) {
    out.ib.startVec(c);
    for (const auto& [r, v] : ib_cols[c]) out.ib.insertBack(r, c) = v;
  }
  out.ib.finalize();
  return out;
}

SparseMatrix Unpartition(const Blocks& blocks, const std::vector<int>& interior,
                         const std::vector<int>& interior_index) {
  const int n = int(interior_index.size());
  const std::vector<Eigen::Triplet<double>>& rest = blocks.rest;
  SparseMatrix A(n, n);
  A.reserve(blocks.ii.nonZeros() + long(rest.size()));
  size_t next = 0;
  for (int col = 0; col < n; ++col) {
    A.startVec(col);
    const auto rest_row = [&]() { return next < rest.size() && rest[next].col() == col ? rest[next].row() : n; };
    if (interior_index[col] >= 0) {
      for (SparseMatrix::InnerIterator it(blocks.ii, interior_index[col]); it; ++it) {
        const int row = interior[it.row()];
        for (; rest_row() < row; ++next) A.insertBack(rest[next].row(), col) = rest[next].value();
        A.insertBack(row, col) = it.value();
      }
    }
    for (; rest_row() < n; ++next) A.insertBack(rest[next].row(), col) = rest[next].value();
  }
  A.finalize();
  A.makeCompressed();
  return A;
}

HeldAsBlocks::HeldAsBlocks(FeModel* model, const Blocks& K, const Blocks& M, const std::vector<int>& interior,
                           const std::vector<int>& interior_index)
    : model_(model), K_(K), M_(M), interior_(interior), interior_index_(interior_index) {
  if (!model_) return;
  // Empty matrices of the same size (n_dofs() is K's).
  const long n = model_->K.rows();
  SparseMatrix(n, n).swap(model_->K);
  SparseMatrix(n, n).swap(model_->M);
}

void HeldAsBlocks::Restore() {
  if (!model_) return;
  model_->K = Unpartition(K_, interior_, interior_index_);
  model_->M = Unpartition(M_, interior_, interior_index_);
  model_ = nullptr;
}

}  // namespace femb
