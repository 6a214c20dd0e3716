// The reduced polynomial internal force of a superelement with modal derivatives (issue 6):
// with Green-Lagrange strains the strain energy is exactly quartic in the reduced coordinates q,
//   W(q) = q^T K q / 2 + q^T A z(q) + z(q)^T B z(q),
// z_p = m_p q_j q_k over the pairs p = (j, k), j <= k, ordered (0,0), (0,1), ..., (0,n-1), (1,1),
// ...; m_p = 1 for j = k, 2 for j < k. A (n x P) holds the quadratic and B (P x P, symmetric)
// the cubic coefficients of the force f = dW/dq; P = n (n + 1) / 2 (the symmetry of the pair
// (j, k) is used; reducer/fe/nonlinear_solid.h computes them).
#pragma once

#include <Eigen/Core>

namespace femb {

struct PolynomialStiffness {
  Eigen::MatrixXd A, B;
  int n() const { return int(A.rows()); }
};

/// z(q), P entries.
Eigen::VectorXd PairProducts(const Eigen::VectorXd& q);
double PolynomialEnergy(const Eigen::MatrixXd& K, const PolynomialStiffness& p, const Eigen::VectorXd& q);
/// f(q) = K q + A z + J^T (A^T q) + 2 J^T B z, J = dz/dq.
Eigen::VectorXd PolynomialForce(const Eigen::MatrixXd& K, const PolynomialStiffness& p, const Eigen::VectorXd& q);
/// df/dq (symmetric).
Eigen::MatrixXd PolynomialTangent(const Eigen::MatrixXd& K, const PolynomialStiffness& p, const Eigen::VectorXd& q);

}  // namespace femb
