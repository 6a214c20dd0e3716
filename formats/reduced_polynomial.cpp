#include "formats/reduced_polynomial.h"

namespace femb {
namespace {

// J = dz/dq (P x n): row p = (j, k) holds m_p q_k at column j and m_p q_j at column k.
Eigen::MatrixXd PairJacobian(const Eigen::VectorXd& q) {
  const int n = int(q.size());
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(n * (n + 1) / 2, n);
  int p = 0;
  for (int j = 0; j < n; ++j)
    for (int k = j; k < n; ++k, ++p) {
      const double m = j == k ? 1.0 : 2.0;
      J(p, j) += m * q[k];
      J(p, k) += m * q[j];
    }
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
  return 0.5 * q.dot(K * q) + q.dot(p.A * z) + z.dot(p.B * z);
}

Eigen::VectorXd PolynomialForce(const Eigen::MatrixXd& K, const PolynomialStiffness& p, const Eigen::VectorXd& q) {
  const Eigen::VectorXd z = PairProducts(q);
  const Eigen::MatrixXd J = PairJacobian(q);
  return K * q + p.A * z + J.transpose() * (p.A.transpose() * q + 2 * (p.B * z));
}

Eigen::MatrixXd PolynomialTangent(const Eigen::MatrixXd& K, const PolynomialStiffness& p, const Eigen::VectorXd& q) {
  const Eigen::VectorXd z = PairProducts(q);
  const Eigen::MatrixXd J = PairJacobian(q);
  const Eigen::MatrixXd AJ = p.A * J;
  Eigen::MatrixXd T = K + AJ + AJ.transpose() + 2 * J.transpose() * p.B * J;
  AddPairHessian(p.A.transpose() * q + 2 * (p.B * z), &T);
  return 0.5 * (T + T.transpose());
}

}  // namespace femb
