// The independent reference of the rotating-beam checks: the lowest bending
// eigenvalue omega^2 of a straight Euler-Bernoulli beam rotating steadily about an axis through
// its root, perpendicular to it, from a 1-D model of cubic Hermite elements (converged: 200
// elements agree with 400 to 1e-7):
//   (K_b + K_G(N) - in_plane Omega^2 M) w = omega^2 M w,
//   N(x) = rho A Omega^2 (L^2 - x^2) / 2 + axial_force   (centrifugal tension plus a tip force),
// K_G = int N w'^2 (4-point Gauss, exact for the quadratic N), clamped (w, w' = 0) or hinged
// (w = 0) at the root; in-plane: the centrifugal softening of the displacement in the plane of
// rotation. A hinged in-plane beam's rigid swing (omega ~ 0) is skipped. Header-only: shared by
// tests/solver/analysis/exact_inertia_test.cpp and benchmarks/rotating_cantilever_frequency.cpp.
#pragma once

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>

namespace femb::reference {

inline double RotatingBeamOmega2(double EI, double rhoA, double L, double Omega, bool in_plane, bool hinged = false,
                                 double axial_force = 0.0, int elements = 200) {
  const double h = L / elements;
  const int all = 2 * (elements + 1), first = hinged ? 1 : 2;  // (w, w') per node; root removed
  const int dofs = all - first;
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(dofs, dofs), M = K;
  Eigen::Matrix4d ke, me;
  ke << 12, 6 * h, -12, 6 * h, 6 * h, 4 * h * h, -6 * h, 2 * h * h, -12, -6 * h, 12, -6 * h, 6 * h, 2 * h * h, -6 * h,
      4 * h * h;
  ke *= EI / (h * h * h);
  me << 156, 22 * h, 54, -13 * h, 22 * h, 4 * h * h, 13 * h, -3 * h * h, 54, 13 * h, 156, -22 * h, -13 * h, -3 * h * h,
      -22 * h, 4 * h * h;
  me *= rhoA * h / 420;
  const double gp[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
  const double gw[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};
  for (int e = 0; e < elements; ++e) {
    Eigen::Matrix4d k = ke;
    for (int g = 0; g < 4; ++g) {
      const double s = 0.5 * (gp[g] + 1), x = (e + s) * h;
      const double N = rhoA * Omega * Omega * (L * L - x * x) / 2 + axial_force;
      Eigen::Vector4d dN;  // d/dx of the Hermite shape functions
      dN << (-6 * s + 6 * s * s) / h, 1 - 4 * s + 3 * s * s, (6 * s - 6 * s * s) / h, -2 * s + 3 * s * s;
      k += 0.5 * gw[g] * h * N * dN * dN.transpose();
    }
    if (in_plane) k -= Omega * Omega * me;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) {
        const int I = 2 * e + i - first, J = 2 * e + j - first;
        if (I < 0 || J < 0) continue;
        K(I, J) += k(i, j);
        M(I, J) += me(i, j);
      }
  }
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(K, M, Eigen::EigenvaluesOnly);
  const double scale = EI / (rhoA * L * L * L * L);  // omega^2 units of the beam
  for (int i = 0; i < eig.eigenvalues().size(); ++i) {
    if (!(hinged && in_plane) || eig.eigenvalues()[i] > 1e-3 * scale) return eig.eigenvalues()[i];
  }
  return 0.0;
}

}  // namespace femb::reference
