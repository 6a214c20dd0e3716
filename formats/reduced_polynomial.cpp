#include "formats/reduced_polynomial.h"

#include <Eigen/SparseCore>
#include <vector>

namespace femb {
namespace {

// J = dz/dq (P x n), sparse: row p = (j, k) holds m_p q_k at column j and m_p q_j at column k.
// (Dense, J^T B J would cost P^2 n flops; sparse, P n^2.)
Eigen::SparseMatrix<double> PairJacobian(const Eigen::VectorXd& q) {
  const int n = int(q.size());
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(size_t(n) * (n + 1));
  int p = 0;
  for (int j = 0; j < n; ++j)
    for (int k = j; k < n; ++k, ++p) {
      const double m = j == k ? 1.0 : 2.0;
      entries.emplace_back(p, j, m * q[k]);
      entries.emplace_back(p, k, m * q[j]);
    }
  Eigen::SparseMatrix<double> J(n * (n + 1) / 2, n);
  J.setFromTriplets(entries.begin(), entries.end());  // sums the two entries of a diagonal pair
  return J;
}

// Adds sum_p w_p d2 z_p / dq2 to T: m_p at (j, k) and (k, j).
void AddPairHessian(const Eigen::VectorXd& w, Eigen::MatrixXd* T) {
  const int n = int(T->rows());
  int p = 0;
  for (int j = 0; j < n; ++j)
    for (int k = j; k < n; ++k, ++p) {
      const double m = j == k ? 1.0 : 2.0;
      (*T)(j, k) += m * w[p];
      (*T)(k, j) += m * w[p];
    }
}

}  // namespace

Eigen::VectorXd PairProducts(const Eigen::VectorXd& q) {
  const int n = int(q.size());
  Eigen::VectorXd z(n * (n + 1) / 2);
  int p = 0;
  for (int j = 0; j < n; ++j)
    for (int k = j; k < n; ++k, ++p) z[p] = (j == k ? 1.0 : 2.0) * q[j] * q[k];
  return z;
}

double PolynomialEnergy(const Eigen::MatrixXd& K, const PolynomialStiffness& p, const Eigen::VectorXd& q) {
  const Eigen::VectorXd z = PairProducts(q);
  return 0.5 * q.dot(K * q) + q.dot(p.A * z) + (p.cubic() ? z.dot(p.B * z) : 0.0);
}

Eigen::VectorXd PolynomialForce(const Eigen::MatrixXd& K, const PolynomialStiffness& p, const Eigen::VectorXd& q) {
  const Eigen::VectorXd z = PairProducts(q);
  const Eigen::SparseMatrix<double> J = PairJacobian(q);
  if (!p.cubic()) return K * q + J.transpose() * (p.A.transpose() * q);  // geometric stiffness form
  const Eigen::VectorXd w = p.A.transpose() * q + 2 * (p.B * z);
  return K * q + p.A * z + J.transpose() * w;
}

Eigen::MatrixXd PolynomialTangent(const Eigen::MatrixXd& K, const PolynomialStiffness& p, const Eigen::VectorXd& q) {
  const Eigen::VectorXd z = PairProducts(q);
  const Eigen::SparseMatrix<double> J = PairJacobian(q);
  const Eigen::MatrixXd AJ = p.A * J;
  if (!p.cubic()) {
    // d/dq [J^T (A^T q)] = (A J)^T + sum_p (A^T q)_p d2 z_p / dq2 (not symmetric).
    Eigen::MatrixXd T = K + AJ.transpose();
    AddPairHessian(p.A.transpose() * q, &T);
    return T;
  }
  const Eigen::MatrixXd BJ = p.B * J;
  Eigen::MatrixXd T = K + AJ + AJ.transpose();
  T.noalias() += 2 * (J.transpose() * BJ);
  AddPairHessian(p.A.transpose() * q + 2 * (p.B * z), &T);
  return 0.5 * (T + T.transpose());
}

}  // namespace femb
