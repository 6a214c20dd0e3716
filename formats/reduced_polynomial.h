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

// Without modal derivatives, the geometric stiffening of issue 13 stores the quadratic part A
// only (B empty, 0 x 0). A holds the third-order tensor of the geometric stiffness of each basis
// vector's stress: K_sigma,j = Phi^T G(sigma(phi_j)) Phi has entries (k, l) = 2 A(j, p(k, l)).
// The force used is then the geometric stiffness of the current deformation's stress,
//   f(q) = K q + sum_j q_j K_sigma,j q = K q + J^T (A^T q)   (Wallrapp's K_e1 term of the SID),
// i.e. the Green-Lagrange quadratic force without its foreshortening part A z (the force
// q^T K_sigma,i q / 2 that bending exerts on a stretching coordinate i). Without the quartic
// term that part makes the energy q^T K q / 2 + q^T A z unbounded below as soon as the basis
// holds an axial coordinate (an interface's stretch) beside bending: u' = -v'^2 / 2 then releases
// energy EA v'^4 / 8 (measured: a 1-body tensioned cantilever showed 2 negative tangent
// eigenvalues, and the rotating beam deflected more, not less). The quartic term B of a
// bending-only basis would lock (a stretch that only modal derivatives can relieve), so the full
// polynomial stays with modal derivatives. The tangent of this force is not symmetric.
struct PolynomialStiffness {
  Eigen::MatrixXd A, B;
  int n() const { return int(A.rows()); }
  bool cubic() const { return B.size() > 0; }
};

/// z(q), P entries.
Eigen::VectorXd PairProducts(const Eigen::VectorXd& q);
double PolynomialEnergy(const Eigen::MatrixXd& K, const PolynomialStiffness& p, const Eigen::VectorXd& q);
/// f(q) = K q + A z + J^T (A^T q) + 2 J^T B z, J = dz/dq (cubic); K q + J^T (A^T q) (A only).
Eigen::VectorXd PolynomialForce(const Eigen::MatrixXd& K, const PolynomialStiffness& p, const Eigen::VectorXd& q);
/// df/dq (symmetric for the cubic polynomial).
Eigen::MatrixXd PolynomialTangent(const Eigen::MatrixXd& K, const PolynomialStiffness& p, const Eigen::VectorXd& q);

}  // namespace femb
