#include "reducer/reduction/general_basis.h"

#include <Eigen/Dense>
#include <algorithm>
#include <string>

#include "reducer/linalg/dense_products.h"
#include "reducer/reduction/craig_bampton.h"

namespace femb {

SparseMatrix InterfaceRows(const FeModel& model) {
  const int N = int(model.interface_names.size());
  std::vector<Eigen::Triplet<double>> t;
  for (int k = 0; k < N; ++k) {
    const bool rbe3 = k < int(model.interface_weights.size()) && model.interface_weights[size_t(k)].rows() > 0;
    if (rbe3) {
      const SparseMatrix& W = model.interface_weights[size_t(k)];
      for (int j = 0; j < W.outerSize(); ++j)
        for (SparseMatrix::InnerIterator it(W, j); it; ++it) t.emplace_back(6 * k + int(it.row()), j, it.value());
    } else {
      for (int d = 0; d < 6; ++d) t.emplace_back(6 * k + d, model.interface_dofs[size_t(k)][size_t(d)].value, 1.0);
    }
  }
  SparseMatrix B(6 * N, model.n_dofs());
  B.setFromTriplets(t.begin(), t.end());
  return B;
}

GeneralBasisResult ReduceOnGeneralBasis(const FeModel& model, const Eigen::MatrixXd& V_given,
                                        const Eigen::MatrixXd* static_modes) {
  GeneralBasisResult r;
  const int N = int(model.interface_names.size()), nb = 6 * N;
  // 1. Rigid-body fields appended; M-orthonormal, dependent columns dropped.
  Eigen::MatrixXd V(model.n_dofs(), 6 + V_given.cols());
  V << RigidFields(model), V_given;
  r.columns_given = int(V_given.cols());
  const Eigen::MatrixXd MV = model.M * V;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> gram(TransposeTimes(V, MV));
  const Eigen::VectorXd g = gram.eigenvalues();
  const double g_max = g.maxCoeff();
  std::vector<int> keep;
  for (int k = 0; k < g.size(); ++k)
    if (g[k] > 1e-10 * g_max) keep.push_back(k);
  Eigen::MatrixXd Q(V.rows(), long(keep.size()));
  for (size_t j = 0; j < keep.size(); ++j)
    Q.col(long(j)) = V * gram.eigenvectors().col(keep[j]) / std::sqrt(g[keep[j]]);
  r.columns_kept = int(Q.cols());

  // 2. The interface span (8.12) and its SVD, rotation rows scaled by the part's size L so that
  // the rank and the constraint do not depend on the units.
  double L = 0.0;
  if (model.nodes.rows() > 1) L = (model.nodes.colwise().maxCoeff() - model.nodes.colwise().minCoeff()).norm();
  if (!(L > 0)) L = 1.0;
  Eigen::VectorXd scale(nb);
  for (int k = 0; k < N; ++k) scale.segment<6>(6 * k) << 1, 1, 1, L, L, L;
  const SparseMatrix B = InterfaceRows(model);
  const Eigen::MatrixXd Phi_IP = scale.asDiagonal() * (B * Q);  // 6N x M, lengths
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(Phi_IP, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::VectorXd s = svd.singularValues();
  const double s_max = s.size() ? s[0] : 0.0;
  int m = 0;
  for (int k = 0; k < s.size(); ++k) m += s[k] > 1e-8 * s_max;
  r.interface_rank = m;
  const int n_constraints = nb - m;
  if (n_constraints > 0) {
    // Case 4: C = E L with E the reduced row echelon form of U_2^T (Gauss-Jordan, full pivoting)
    // with unit rows: the same constraint, but each row on as few coordinates as the null space
    // allows (a rod: A.u_x - B.u_x and A.theta_x - B.theta_x, not two mixtures of them).
    Eigen::MatrixXd E = svd.matrixU().rightCols(n_constraints).transpose();
    std::vector<bool> used(size_t(nb), false);
    for (int i = 0; i < n_constraints; ++i) {
      int pr = i, pc = 0;
      double best = -1.0;
      for (int a = i; a < n_constraints; ++a)
        for (int b = 0; b < nb; ++b)
          if (!used[size_t(b)] && std::abs(E(a, b)) > best) best = std::abs(E(a, b)), pr = a, pc = b;
      E.row(i).swap(E.row(pr));
      used[size_t(pc)] = true;
      E.row(i) /= E(i, pc);
      for (int a = 0; a < n_constraints; ++a)
        if (a != i) E.row(a) -= E(a, pc) * E.row(i);
    }
    for (int i = 0; i < n_constraints; ++i) E.row(i).normalize();
    r.constraint_length = L;
    r.interface_constraint = E * scale.asDiagonal();
    for (int i = 0; i < n_constraints; ++i) {
      const Eigen::VectorXd w = E.row(i).cwiseAbs().transpose();
      std::vector<int> at;
      for (int k = 0; k < nb; ++k)
        if (w[k] >= 0.5 * w.maxCoeff()) at.push_back(k);
      std::sort(at.begin(), at.end(), [&](int a, int b) { return w[a] > w[b]; });
      r.constraint_direction.push_back(at);
    }
  }
  const long n_internal = Q.cols() - m;
  // Phi0 = Q (L Phi_IP)^+ L = Q V_s S^-1 U_1^T L; Psi0 = Q N (the right singular vectors past the rank).
  const Eigen::MatrixXd pinv = svd.matrixV().leftCols(m) * s.head(m).cwiseInverse().asDiagonal() *
                               svd.matrixU().leftCols(m).transpose() * scale.asDiagonal();
  Eigen::MatrixXd Phi = Q * pinv;
  if (n_constraints > 0 && static_modes) {
    // The constrained directions' field: the static modes' (B Psi_c = 1), so B Phi = 1.
    const Eigen::MatrixXd U2 = svd.matrixU().rightCols(n_constraints);
    Phi += *static_modes * (scale.cwiseInverse().asDiagonal() * U2 * r.interface_constraint);
  }
  Eigen::MatrixXd Psi = Q * svd.matrixV().rightCols(n_internal);

  // 3. Condensation within the basis; 4. internal eigen-coordinates. K enters through K Phi and
  // K Psi alone, each product taken once and carried along the changes of basis.
  Eigen::MatrixXd K_Phi = model.K * Phi;
  Eigen::MatrixXd K_Psi(model.n_dofs(), 0);
  if (n_internal > 0) {
    K_Psi = model.K * Psi;
    const Eigen::MatrixXd PtKP = TransposeTimes(Psi, K_Psi);
    const Eigen::MatrixXd Kpp = 0.5 * (PtKP + PtKP.transpose());
    const Eigen::MatrixXd Mpp = TransposeTimes(Psi, Eigen::MatrixXd(model.M * Psi));
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(Kpp, 0.5 * (Mpp + Mpp.transpose()));
    if (eig.info() != Eigen::Success || !(eig.eigenvalues().minCoeff() > 0)) {
      r.message =
          "the shapes' internal part (zero at the interfaces) has no stiffness in some direction (a mechanism "
          "or a dependent shape): the basis cannot carry it";
      r.input_error = true;
      return r;
    }
    Psi = Times(Psi, eig.eigenvectors());  // K = diag(lambda), M = 1 on the internal block
    K_Psi = Times(K_Psi, eig.eigenvectors());
    r.lambda = eig.eigenvalues();
    const Eigen::MatrixXd C = r.lambda.cwiseInverse().asDiagonal() * TransposeTimes(Psi, K_Phi);
    Gemm(Psi, false, C, false, Phi, -1.0, 1.0);
    Gemm(K_Psi, false, C, false, K_Phi, -1.0, 1.0);
  }
  r.shapes.resize(model.n_dofs(), nb + n_internal);
  r.shapes << Phi, Psi;
  Eigen::MatrixXd KS(model.n_dofs(), nb + n_internal);
  KS << K_Phi, K_Psi;
  const Eigen::MatrixXd MS = model.M * r.shapes;
  r.K = TransposeTimes(r.shapes, KS);
  r.M = TransposeTimes(r.shapes, MS);
  r.K = 0.5 * (r.K + r.K.transpose()).eval();
  r.M = 0.5 * (r.M + r.M.transpose()).eval();
  r.ok = true;
  return r;
}

}  // namespace femb
