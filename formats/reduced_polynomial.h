// The reduced polynomial internal force of a superelement with modal derivatives:
// with Green-Lagrange strains the strain energy is exactly quartic in the reduced coordinates q,
//   W(q) = q^T K q / 2 + q^T A z(q) + z(q)^T B z(q),
// z_p = m_p q_j q_k over the pairs p = (j, k), j <= k, ordered (0,0), (0,1), ..., (0,n-1), (1,1),
// ...; m_p = 1 for j = k, 2 for j < k. A (n x P) holds the quadratic and B (P x P, symmetric)
// the cubic coefficients of the force f = dW/dq; P = n (n + 1) / 2 (the symmetry of the pair
// (j, k) is used; reducer/fe/nonlinear_solid.h computes them).
#pragma once

#include <Eigen/Core>

namespace femb {

// Without modal derivatives, the geometric stiffening stores the quadratic part A
// only (B empty, 0 x 0). A holds the third-order tensor of the geometric stiffness of each basis
// vector's stress: K_sigma,j = Phi^T G(sigma(phi_j)) Phi has entries (k, l) = 2 A(j, p(k, l)),
// and (A z)_i = q^T K_sigma,i q / 2 is the force that the deformation's quadratic strain exerts
// on coordinate i (e.g. the shortening that bending imposes on an interface's stretch).
//
// The energy used is the Green-Lagrange energy up to its cubic term, completed to a square with
// the part of the quartic term that the basis itself can represent (a static condensation of
// the quadratic strain onto the basis, the reduced-space analogue of the quadratic manifold of
// Jain, Tiso and Rutzmoser, 2017):
//   W(q) = eps^T K eps / 2,   eps = q + K^+ A z(q)
//        = q^T K q / 2 + q^T A z + (A z)^T K^+ (A z) / 2        (K K^+ A z = A z: rigid fields
//                                                                  have no stress),
//   f = dW/dq = E^T K eps = K eps + J^T (A^T eps),  E = d eps / dq = 1 + K^+ A J,  J = dz/dq,
//   K_t = E^T K E + sum_p (A^T eps)_p d2 z_p / dq2   (symmetric; A^T K^+ K = A^T: rigid fields
//   have no stress).
// To second order f is the Green-Lagrange quadratic force K q + A z + J^T (A^T q): the geometric
// stiffness of the current stress and its reciprocal, the shortening force. The quartic part of
// the square is what keeps the energy bounded below: with the cubic term alone, an axial
// coordinate (an interface's stretch) beside bending releases EA v'^4 / 8 through u' = -v'^2 / 2
// (measured: 2 negative tangent eigenvalues on a 1-body tensioned cantilever). It is a lower
// bound of the true quartic z^T B z, whose excess (membrane strain the basis cannot carry) would
// lock a bending-only basis; the full polynomial stays with modal derivatives. W >= 0, so a
// stiffened body conserves energy like a linear one (the geometric stiffness form
// K q + J^T (A^T q) is not a gradient, and pumps a four-bar coupler's bending until the run
// stops: benchmarks/stiffening_energy.py).
struct PolynomialStiffness {
  Eigen::MatrixXd A, B;
  /// Without B: a root R of K^+, the pseudo-inverse of the reduced stiffness, K^+ = R^T R (rank
  /// rows; WithCondensation).
  Eigen::MatrixXd K_plus_root;
  int n() const { return int(A.rows()); }
  bool cubic() const { return B.size() > 0; }
};

/// p with the root of K^+ set when it is quadratic (A only): the eigenvalues of K below 1e-10 of
/// the largest (the rigid fields) are left out.
PolynomialStiffness WithCondensation(const Eigen::MatrixXd& K, PolynomialStiffness p);

/// The coordinates whose linear stress is the body's: eps = q + K^+ A z for the condensed
/// quadratic polynomial (the membrane strain its basis carries, e.g. a bent member's shortening),
/// q for the cubic one (whose stress recovery keeps the strain's quadratic part itself).
Eigen::VectorXd StressCoordinates(const PolynomialStiffness& p, const Eigen::VectorXd& q);
/// z(q), P entries.
Eigen::VectorXd PairProducts(const Eigen::VectorXd& q);
double PolynomialEnergy(const Eigen::MatrixXd& K, const PolynomialStiffness& p, const Eigen::VectorXd& q);
/// f(q) = K q + A z + J^T (A^T q) + 2 J^T B z, J = dz/dq (cubic); E^T K eps (A only, above).
Eigen::VectorXd PolynomialForce(const Eigen::MatrixXd& K, const PolynomialStiffness& p, const Eigen::VectorXd& q);
/// df/dq (symmetric).
Eigen::MatrixXd PolynomialTangent(const Eigen::MatrixXd& K, const PolynomialStiffness& p, const Eigen::VectorXd& q);
/// The condensed quadratic polynomial's force and tangent at q with its eps = StressCoordinates(p, q)
/// already at hand (a body evaluates it once per iteration).
Eigen::VectorXd CondensedForce(const Eigen::MatrixXd& K, const PolynomialStiffness& p, const Eigen::VectorXd& q,
                               const Eigen::VectorXd& eps);
Eigen::MatrixXd CondensedTangent(const Eigen::MatrixXd& K, const PolynomialStiffness& p, const Eigen::VectorXd& q,
                                 const Eigen::VectorXd& eps);

/// The temporaries of the condensed polynomial's functions below, kept by the caller from call
/// to call so that they allocate nothing once sized (a body's Data). Contents mean
/// nothing between calls.
struct PolynomialScratch {
  Eigen::VectorXd z, Az, RAz, Ate, u;
  Eigen::MatrixXd AJ, RAJ;
};
/// The same as StressCoordinates (condensed: eps = q + K^+ A z), CondensedForce and
/// CondensedTangent, into their outputs' storage; the same numbers.
void CondensedCoordinates(const PolynomialStiffness& p, const Eigen::VectorXd& q, Eigen::VectorXd& eps,
                          PolynomialScratch& s);
void CondensedForce(const Eigen::MatrixXd& K, const PolynomialStiffness& p, const Eigen::VectorXd& q,
                    const Eigen::VectorXd& eps, Eigen::VectorXd& f, PolynomialScratch& s);
void CondensedTangent(const Eigen::MatrixXd& K, const PolynomialStiffness& p, const Eigen::VectorXd& q,
                      const Eigen::VectorXd& eps, Eigen::MatrixXd& T, PolynomialScratch& s);

}  // namespace femb
