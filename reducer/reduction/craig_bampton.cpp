#include "reducer/reduction/craig_bampton.h"

#include <cstdio>

#include "reducer/linalg/generalized_eigen.h"

namespace femb {
namespace {

std::string Format(const char* fmt, double a, double b = 0, double c = 0, double d = 0) {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, fmt, a, b, c, d);
  return buffer;
}

// Splits A into the blocks named by the partition (-1: boundary position, else interior index).
struct Blocks {
  SparseMatrix ii, ib;
  Eigen::MatrixXd bb;
};

Blocks Partition(const SparseMatrix& A, const std::vector<int>& interior_index,
                 const std::vector<int>& boundary_index, int n_i, int n_b) {
  // Interior and boundary indices keep the order of A, so each block fills column by column
  // with rows ascending: built in place, no triplet list (A may hold 1e8 entries).
  Blocks out;
  out.bb = Eigen::MatrixXd::Zero(n_b, n_b);
  out.ii.resize(n_i, n_i);
  out.ib.resize(n_i, n_b);
  out.ii.reserve(A.nonZeros());
  std::vector<std::vector<std::pair<int, double>>> ib_cols(n_b);
  for (int col = 0; col < A.outerSize(); ++col) {
    const int ci = interior_index[col], cb = boundary_index[col];
    if (ci >= 0) out.ii.startVec(ci);
    for (SparseMatrix::InnerIterator it(A, col); it; ++it) {
      const int ri = interior_index[it.row()], rb = boundary_index[it.row()];
      if (ri >= 0 && ci >= 0) {
        out.ii.insertBack(ri, ci) = it.value();
      } else if (ri >= 0 && cb >= 0) {
        ib_cols[cb].emplace_back(ri, it.value());
      } else if (rb >= 0 && cb >= 0) {
        out.bb(rb, cb) += it.value();
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

}  // namespace

std::vector<int> InteriorDofs(const FeModel& model) {
  std::vector<char> is_boundary(model.n_dofs(), 0);
  for (const auto& dofs : model.interface_dofs) {
    for (FullDof d : dofs) is_boundary[d.value] = 1;
  }
  std::vector<int> interior;
  for (int d = 0; d < model.n_dofs(); ++d) {
    if (!is_boundary[d]) interior.push_back(d);
  }
  return interior;
}

CraigBamptonResult CraigBamptonReduce(const FeModel& model, int internal_modes,
                                      const ProgressFn& progress, long dense_limit, double memory_limit_bytes) {
  CraigBamptonResult r;
  Stopwatch clock;
  const int n = int(model.n_dofs());
  std::vector<int> boundary;
  for (const auto& dofs : model.interface_dofs) {
    for (FullDof d : dofs) boundary.push_back(d.value);
  }
  const std::vector<int> interior = InteriorDofs(model);
  const int n_b = int(boundary.size()), n_i = int(interior.size());
  std::vector<int> interior_index(n, -1), boundary_index(n, -1);
  for (int k = 0; k < n_i; ++k) interior_index[interior[k]] = k;
  for (int k = 0; k < n_b; ++k) boundary_index[boundary[k]] = k;
  if (internal_modes > n_i) {
    r.message = "reduction.internal_modes = " + std::to_string(internal_modes) + " exceeds the " +
                std::to_string(n_i) + " interior DOFs of the model";
    return r;
  }

  const Blocks K = Partition(model.K, interior_index, boundary_index, n_i, n_b);
  const Blocks M = Partition(model.M, interior_index, boundary_index, n_i, n_b);

  // One factorization of K_ii (METIS ordering, supernodal).
  clock.Restart();
  SparseCholesky factor;
  r.factorization = factor.Compute(K.ii, memory_limit_bytes);
  const double t_factor = clock.Seconds();
  if (r.factorization.too_big) {
    r.message = r.factorization.message;
    return r;
  }
  if (!r.factorization.ok) {
    r.message = "K_ii (stiffness with all interfaces clamped) is singular: " + r.factorization.message +
                "; some part of the model is not held by any interface";
    return r;
  }
  if (progress) {
    progress("factorize K_ii", t_factor,
             Format("%.0f interior DOFs, factor %.3g MB, %.3g GFLOP, %.2f GFLOP/s", n_i,
                    r.factorization.factor_bytes / 1e6, r.factorization.flops / 1e9,
                    r.factorization.flops / 1e9 / std::max(r.factorization.numeric_seconds, 1e-9)) +
                 Format(" (numeric %.3g s; ordering %.3g s, ", r.factorization.numeric_seconds,
                        r.factorization.analyze_seconds) +
                 r.factorization.ordering + ")");
  }

  // Static constraint modes Psi_c = -K_ii^-1 K_ib.
  clock.Restart();
  const Eigen::MatrixXd Psi_c = -factor.Solve(Eigen::MatrixXd(K.ib));
  if (progress) progress("static modes", clock.Seconds(), Format("%.0f constraint modes", n_b));

  // Fixed-interface modes, shift-invert around 0 on the same factor.
  clock.Restart();
  const EigenResult eig = LowestEigenpairs(K.ii, M.ii, internal_modes, 0.0, factor, dense_limit);
  if (!eig.ok) {
    r.message = "fixed-interface eigen solve failed: " + eig.message;
    return r;
  }
  r.lambda = eig.lambda;
  r.eigen_linear_solves = eig.linear_solves;
  r.dense_eigen = eig.dense;
  const Eigen::MatrixXd& Phi_i = eig.vectors;
  if (progress) {
    progress("eigen solve", clock.Seconds(),
             Format("%.0f fixed-interface modes, %.0f linear solves (%.1f per mode)", internal_modes,
                    double(eig.linear_solves), double(eig.linear_solves) / std::max(internal_modes, 1)) +
                 (eig.dense ? ", dense solver (small interior)" : ", shift-invert Lanczos"));
  }

  // Projection.
  clock.Restart();
  const int m = internal_modes, n_r = n_b + m;
  r.K = Eigen::MatrixXd::Zero(n_r, n_r);
  r.M = Eigen::MatrixXd::Zero(n_r, n_r);
  const Eigen::MatrixXd Mii_Psi = M.ii * Psi_c;
  const Eigen::MatrixXd K_ib_dense(K.ib), M_ib_dense(M.ib);
  r.K.topLeftCorner(n_b, n_b) = K.bb + K_ib_dense.transpose() * Psi_c;
  for (int k = 0; k < m; ++k) r.K(n_b + k, n_b + k) = r.lambda[k];
  r.M.topLeftCorner(n_b, n_b) =
      M.bb + M_ib_dense.transpose() * Psi_c + Psi_c.transpose() * M_ib_dense + Psi_c.transpose() * Mii_Psi;
  if (m > 0) {
    const Eigen::MatrixXd M_bq = (M_ib_dense.transpose() + Mii_Psi.transpose()) * Phi_i;
    r.M.block(0, n_b, n_b, m) = M_bq;
    r.M.block(n_b, 0, m, n_b) = M_bq.transpose();
    r.M.bottomRightCorner(m, m) = Phi_i.transpose() * (M.ii * Phi_i);
  }
  r.K = 0.5 * (r.K + r.K.transpose()).eval();
  r.M = 0.5 * (r.M + r.M.transpose()).eval();

  r.shapes = Eigen::MatrixXd::Zero(n, n_r);
  for (int k = 0; k < n_b; ++k) r.shapes(boundary[k], k) = 1.0;
  for (int k = 0; k < n_i; ++k) {
    r.shapes.row(interior[k]).head(n_b) = Psi_c.row(k);
    if (m > 0) r.shapes.row(interior[k]).tail(m) = Phi_i.row(k);
  }
  if (progress) progress("projection", clock.Seconds(), Format("%.0f reduced DOFs", n_r));
  r.ok = true;
  return r;
}

}  // namespace femb
