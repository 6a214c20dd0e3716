#include "formats/reduced_polynomial.h"

#include <Eigen/Eigenvalues>
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

// J^T v without forming J, into `out`: per pair p = (j, k), m_p q_k v_p to entry j and m_p q_j
// v_p to entry k (2 q_j v_p once for a diagonal pair).
void PairJacobianTransposeTimes(const Eigen::VectorXd& q, const Eigen::VectorXd& v, Eigen::VectorXd& out) {
  const int n = int(q.size());
  out.setZero(n);
  int p = 0;
  for (int j = 0; j < n; ++j) {
    out[j] += 2.0 * q[j] * v[p++];
    for (int k = j + 1; k < n; ++k, ++p) {
      out[j] += 2.0 * q[k] * v[p];
      out[k] += 2.0 * q[j] * v[p];
    }
  }
}

Eigen::VectorXd PairJacobianTransposeTimes(const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
  Eigen::VectorXd out;
  PairJacobianTransposeTimes(q, v, out);
  return out;
}

// A J (rows of A times J) without forming J: column j of A J gathers m_p q_k A_p over the pairs
// p = (j, k) and (k, j).
void TimesPairJacobian(const Eigen::MatrixXd& A, const Eigen::VectorXd& q, Eigen::MatrixXd& out) {
  const int n = int(q.size());
  out.setZero(A.rows(), n);
  int p = 0;
  for (int j = 0; j < n; ++j) {
    out.col(j) += (2.0 * q[j]) * A.col(p++);
    for (int k = j + 1; k < n; ++k, ++p) {
      out.col(j) += (2.0 * q[k]) * A.col(p);
      out.col(k) += (2.0 * q[j]) * A.col(p);
    }
  }
}

Eigen::MatrixXd TimesPairJacobian(const Eigen::MatrixXd& A, const Eigen::VectorXd& q) {
  Eigen::MatrixXd out;
  TimesPairJacobian(A, q, out);
  return out;
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

namespace {
void PairProductsInto(const Eigen::VectorXd& q, Eigen::VectorXd& z) {
  const int n = int(q.size());
  z.resize(n * (n + 1) / 2);
  int p = 0;
  for (int j = 0; j < n; ++j)
    for (int k = j; k < n; ++k, ++p) z[p] = (j == k ? 1.0 : 2.0) * q[j] * q[k];
}
}  // namespace

Eigen::VectorXd PairProducts(const Eigen::VectorXd& q) {
  Eigen::VectorXd z;
  PairProductsInto(q, z);
  return z;
}

PolynomialStiffness WithCondensation(const Eigen::MatrixXd& K, PolynomialStiffness p) {
  if (p.cubic()) return p;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(0.5 * (K + K.transpose()));
  const Eigen::VectorXd& lambda = eig.eigenvalues();
  const double floor = 1e-10 * lambda.cwiseAbs().maxCoeff();
  std::vector<int> kept;
  for (int i = 0; i < int(lambda.size()); ++i)
    if (lambda[i] > floor) kept.push_back(i);
  p.K_plus_root.resize(long(kept.size()), K.cols());
  for (size_t r = 0; r < kept.size(); ++r)
    p.K_plus_root.row(long(r)) = eig.eigenvectors().col(kept[r]).transpose() / std::sqrt(lambda[kept[r]]);
  return p;
}

namespace {
// The condensed quadratic polynomial's eps = q + K^+ A z (header).
Eigen::VectorXd Condensed(const PolynomialStiffness& p, const Eigen::VectorXd& q) {
  Eigen::VectorXd eps;
  PolynomialScratch s;
  CondensedCoordinates(p, q, eps, s);
  return eps;
}
}  // namespace

Eigen::VectorXd StressCoordinates(const PolynomialStiffness& p, const Eigen::VectorXd& q) {
  return p.cubic() ? q : Condensed(p, q);
}

double PolynomialEnergy(const Eigen::MatrixXd& K, const PolynomialStiffness& p, const Eigen::VectorXd& q) {
  if (!p.cubic()) {
    const Eigen::VectorXd eps = Condensed(p, q);
    return 0.5 * eps.dot(K * eps);
  }
  const Eigen::VectorXd z = PairProducts(q);
  return 0.5 * q.dot(K * q) + q.dot(p.A * z) + z.dot(p.B * z);
}

Eigen::VectorXd PolynomialForce(const Eigen::MatrixXd& K, const PolynomialStiffness& p, const Eigen::VectorXd& q) {
  if (!p.cubic()) return CondensedForce(K, p, q, Condensed(p, q));
  const Eigen::VectorXd z = PairProducts(q);
  const Eigen::VectorXd w = p.A.transpose() * q + 2 * (p.B * z);
  return K * q + p.A * z + PairJacobianTransposeTimes(q, w);
}

void CondensedCoordinates(const PolynomialStiffness& p, const Eigen::VectorXd& q, Eigen::VectorXd& eps,
                          PolynomialScratch& s) {
  PairProductsInto(q, s.z);
  s.Az.noalias() = p.A * s.z;
  s.RAz.noalias() = p.K_plus_root * s.Az;
  eps = q;
  eps.noalias() += p.K_plus_root.transpose() * s.RAz;
}

void CondensedForce(const Eigen::MatrixXd& K, const PolynomialStiffness& p, const Eigen::VectorXd& q,
                    const Eigen::VectorXd& eps, Eigen::VectorXd& f, PolynomialScratch& s) {
  // E^T K eps = K eps + J^T (A^T K^+ K eps) = K eps + J^T (A^T eps): K^+ K is the projection
  // off the rigid fields, and a rigid field has no stress (A^T of it vanishes).
  s.Ate.noalias() = p.A.transpose() * eps;
  PairJacobianTransposeTimes(q, s.Ate, s.u);
  f.noalias() = K * eps;
  f += s.u;
}

void CondensedTangent(const Eigen::MatrixXd& K, const PolynomialStiffness& p, const Eigen::VectorXd& q,
                      const Eigen::VectorXd& eps, Eigen::MatrixXd& T, PolynomialScratch& s) {
  // E^T K E = K + A J + (A J)^T + (A J)^T K^+ (A J) (K K^+ A J = A J: the columns of A J, the
  // derivatives of A z, have no rigid part), plus the pair Hessian at A^T eps (as the force).
  TimesPairJacobian(p.A, q, s.AJ);
  T = K + s.AJ + s.AJ.transpose();
  s.RAJ.noalias() = p.K_plus_root * s.AJ;
  T.noalias() += s.RAJ.transpose() * s.RAJ;
  s.Ate.noalias() = p.A.transpose() * eps;
  AddPairHessian(s.Ate, &T);
  // 0.5 (T + T^T) in place, entry pair by entry pair (the same numbers).
  const Eigen::Index n = T.rows();
  for (Eigen::Index j = 0; j < n; ++j)
    for (Eigen::Index k = j + 1; k < n; ++k) T(j, k) = T(k, j) = 0.5 * (T(j, k) + T(k, j));
}

Eigen::VectorXd CondensedForce(const Eigen::MatrixXd& K, const PolynomialStiffness& p, const Eigen::VectorXd& q,
                               const Eigen::VectorXd& eps) {
  Eigen::VectorXd f;
  PolynomialScratch s;
  CondensedForce(K, p, q, eps, f, s);
  return f;
}

Eigen::MatrixXd CondensedTangent(const Eigen::MatrixXd& K, const PolynomialStiffness& p, const Eigen::VectorXd& q,
                                 const Eigen::VectorXd& eps) {
  Eigen::MatrixXd T;
  PolynomialScratch s;
  CondensedTangent(K, p, q, eps, T, s);
  return T;
}

Eigen::MatrixXd PolynomialTangent(const Eigen::MatrixXd& K, const PolynomialStiffness& p, const Eigen::VectorXd& q) {
  if (!p.cubic()) return CondensedTangent(K, p, q, Condensed(p, q));
  const Eigen::MatrixXd AJ = TimesPairJacobian(p.A, q);
  const Eigen::VectorXd z = PairProducts(q);
  const Eigen::SparseMatrix<double> J = PairJacobian(q);
  const Eigen::MatrixXd BJ = p.B * J;
  Eigen::MatrixXd T = K + AJ + AJ.transpose();
  T.noalias() += 2 * (J.transpose() * BJ);
  AddPairHessian(p.A.transpose() * q + 2 * (p.B * z), &T);
  return 0.5 * (T + T.transpose());
}

}  // namespace femb
