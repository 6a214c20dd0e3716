// The blocks of the model's K or M that a Craig-Bampton reduction works with (interior-interior,
// interior-boundary), split from the full matrix and joined back, and the model held only as its
// blocks while the interior's factor lives.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

#include "reducer/fe/fe_model.h"

namespace femb {

/// A split into the blocks named by a partition of its DOFs. `rest`: A's entries in a boundary
/// row or column (full indices), column by column with rows ascending, for Unpartition.
struct Blocks {
  SparseMatrix ii, ib;
  std::vector<Eigen::Triplet<double>> rest;
};

/// Splits A by `interior_index` and `boundary_index` (per full DOF: its interior or boundary
/// position, -1 elsewhere), n_i interior and n_b boundary DOFs.
Blocks Partition(const SparseMatrix& A, const std::vector<int>& interior_index, const std::vector<int>& boundary_index,
                 int n_i, int n_b);

/// The matrix that Partition split, from its interior block and the entries it kept of the rest:
/// the same entries with the same values, column by column with rows ascending, as A was.
SparseMatrix Unpartition(const Blocks& blocks, const std::vector<int>& interior,
                         const std::vector<int>& interior_index);

/// The model's K and M held only as their blocks (Partition) while the interior's factor lives:
/// released on construction (when given a model to release them from) and rebuilt from the
/// blocks, the same entries, by Restore or at the end. The peak memory is then lower by K and M.
class HeldAsBlocks {
 public:
  HeldAsBlocks(FeModel* model, const Blocks& K, const Blocks& M, const std::vector<int>& interior,
               const std::vector<int>& interior_index);
  ~HeldAsBlocks() { Restore(); }
  HeldAsBlocks(const HeldAsBlocks&) = delete;
  HeldAsBlocks& operator=(const HeldAsBlocks&) = delete;
  void Restore();

 private:
  FeModel* model_;
  const Blocks &K_, &M_;
  const std::vector<int>&interior_, &interior_index_;
};

}  // namespace femb
