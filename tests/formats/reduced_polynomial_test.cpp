// formats/reduced_polynomial: the pair products' order and multiplicities, and the energy, force
// and tangent of both polynomials against a closed form. The model is the shallow-arch /
// von Karman pair of an axial coordinate u and a bending coordinate v, whose Green-Lagrange energy
// is W = ka (u + v^2 / 2)^2 / 2 + kb v^2 / 2: its cubic term ka u v^2 / 2 is q^T A z with
// A(u, (v, v)) = ka / 2, its quartic term ka v^4 / 8 is z^T B z with B((v,v), (v,v)) = ka / 8 (the
// cubic polynomial), and the condensed quadratic polynomial completes the square exactly
// (eps = q + K^+ A z = (u + v^2 / 2, v)). A third coordinate without stiffness (a rigid field)
// must stay out of K^+.
#include "formats/reduced_polynomial.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>

namespace femb {
namespace {

constexpr double ka = 3.0e4, kb = 7.0;

// Pair index of (j, k), j <= k, in z's order (0,0), (0,1), ..., (0,n-1), (1,1), ...
int Pair(int n, int j, int k) { return j * n - j * (j - 1) / 2 + (k - j); }

Eigen::MatrixXd Stiffness() {
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(3, 3);
  K(0, 0) = ka;
  K(1, 1) = kb;
  return K;  // coordinate 2: a rigid field
}
PolynomialStiffness Condensed() {
  PolynomialStiffness p;
  p.A = Eigen::MatrixXd::Zero(3, 6);
  p.A(0, Pair(3, 1, 1)) = ka / 2;
  return WithCondensation(Stiffness(), p);
}
PolynomialStiffness Cubic() {
  PolynomialStiffness p;
  p.A = Eigen::MatrixXd::Zero(3, 6);
  p.A(0, Pair(3, 1, 1)) = ka / 2;
  p.B = Eigen::MatrixXd::Zero(6, 6);
  p.B(Pair(3, 1, 1), Pair(3, 1, 1)) = ka / 8;
  return p;
}

// The closed forms at q = (u, v, r).
double Energy(const Eigen::Vector3d& q) {
  const double e = q[0] + 0.5 * q[1] * q[1];
  return 0.5 * ka * e * e + 0.5 * kb * q[1] * q[1];
}
Eigen::Vector3d Force(const Eigen::Vector3d& q) {
  const double e = q[0] + 0.5 * q[1] * q[1];
  return {ka * e, ka * e * q[1] + kb * q[1], 0.0};
}
Eigen::Matrix3d Tangent(const Eigen::Vector3d& q) {
  const double e = q[0] + 0.5 * q[1] * q[1], v = q[1];
  Eigen::Matrix3d T = Eigen::Matrix3d::Zero();
  T(0, 0) = ka;
  T(0, 1) = T(1, 0) = ka * v;
  T(1, 1) = ka * v * v + ka * e + kb;
  return T;
}

TEST(ReducedPolynomial, PairProductsInOrderWithMultiplicities) {
  const Eigen::Vector3d q(2.0, 3.0, 5.0);
  const Eigen::VectorXd z = PairProducts(q);
  ASSERT_EQ(z.size(), 6);
  for (int j = 0; j < 3; ++j) {
    for (int k = j; k < 3; ++k) EXPECT_EQ(z[Pair(3, j, k)], (j == k ? 1.0 : 2.0) * q[j] * q[k]) << j << k;
  }
  EXPECT_EQ(Condensed().n(), 3);
  EXPECT_FALSE(Condensed().cubic());
  EXPECT_TRUE(Cubic().cubic());
}

// K^+ = R^T R leaves out the rigid field: R has rank 2 and R^T R is K's pseudo-inverse.
TEST(ReducedPolynomial, CondensationRootIsThePseudoInverse) {
  const PolynomialStiffness p = Condensed();
  ASSERT_EQ(p.K_plus_root.rows(), 2);
  Eigen::Matrix3d expected = Eigen::Matrix3d::Zero();
  expected(0, 0) = 1.0 / ka;
  expected(1, 1) = 1.0 / kb;
  EXPECT_LT((p.K_plus_root.transpose() * p.K_plus_root - expected).norm(), 1e-15 / kb);
  // A cubic polynomial keeps no root.
  EXPECT_EQ(WithCondensation(Stiffness(), Cubic()).K_plus_root.size(), 0);
}

// Both polynomials are the closed form's energy, force and tangent (to round-off: 1e-12
// relative), the condensed one's stress coordinates are (u + v^2 / 2, v, r), and the cubic one's
// are q itself.
TEST(ReducedPolynomial, BothPolynomialsAreTheClosedForm) {
  const Eigen::MatrixXd K = Stiffness();
  for (const Eigen::Vector3d& q :
       {Eigen::Vector3d(1e-4, 0.02, 0.3), Eigen::Vector3d(-3e-3, -0.1, -1.0), Eigen::Vector3d(0.0, 0.5, 0.0)}) {
    for (const PolynomialStiffness& p : {Condensed(), Cubic()}) {
      const double W = Energy(q);
      EXPECT_NEAR(PolynomialEnergy(K, p, q), W, 1e-12 * W) << q.transpose();
      const Eigen::Vector3d f = Force(q);
      EXPECT_LT((PolynomialForce(K, p, q) - f).norm(), 1e-12 * f.norm()) << q.transpose();
      const Eigen::Matrix3d T = Tangent(q);
      const Eigen::MatrixXd Tp = PolynomialTangent(K, p, q);
      EXPECT_LT((Tp - T).norm(), 1e-12 * T.norm()) << q.transpose();
      EXPECT_EQ((Tp - Tp.transpose()).norm(), 0.0);
    }
    const Eigen::Vector3d eps(q[0] + 0.5 * q[1] * q[1], q[1], q[2]);
    EXPECT_LT((StressCoordinates(Condensed(), q) - eps).norm(), 1e-15 * eps.norm());
    EXPECT_EQ(StressCoordinates(Cubic(), q), Eigen::VectorXd(q));
  }
}

// On a random polynomial (no closed form): the force is the energy's gradient and the tangent the
// force's derivative, by central differences (step 1e-6: truncation 1e-12, round-off 1e-10 of the
// force); the energy of the condensed one is eps^T K eps / 2 >= 0 with eps by its definition.
TEST(ReducedPolynomial, ForceIsTheGradientAndTangentTheDerivative) {
  const int n = 4, P = n * (n + 1) / 2;
  srand(11);
  Eigen::MatrixXd L = Eigen::MatrixXd::Random(n, n);
  Eigen::MatrixXd K = L * L.transpose();
  K.row(n - 1).setZero();  // one rigid field
  K.col(n - 1).setZero();
  PolynomialStiffness quadratic;
  quadratic.A = Eigen::MatrixXd::Random(n, P);
  quadratic.A.row(n - 1).setZero();  // rigid fields have no stress
  quadratic = WithCondensation(K, quadratic);
  PolynomialStiffness cubic = quadratic;
  cubic.K_plus_root.resize(0, 0);
  const Eigen::MatrixXd Bh = Eigen::MatrixXd::Random(P, P);
  cubic.B = Bh * Bh.transpose();
  const Eigen::VectorXd q = 0.3 * Eigen::VectorXd::Random(n);
  for (const PolynomialStiffness& p : {quadratic, cubic}) {
    const Eigen::VectorXd f = PolynomialForce(K, p, q);
    const Eigen::MatrixXd T = PolynomialTangent(K, p, q);
    const double h = 1e-6;
    for (int i = 0; i < n; ++i) {
      Eigen::VectorXd plus = q, minus = q;
      plus[i] += h;
      minus[i] -= h;
      const double dW = (PolynomialEnergy(K, p, plus) - PolynomialEnergy(K, p, minus)) / (2 * h);
      EXPECT_NEAR(f[i], dW, 1e-8 * f.norm()) << (p.cubic() ? "cubic " : "condensed ") << i;
      const Eigen::VectorXd df = (PolynomialForce(K, p, plus) - PolynomialForce(K, p, minus)) / (2 * h);
      EXPECT_LT((T.col(i) - df).norm(), 1e-8 * T.norm()) << (p.cubic() ? "cubic " : "condensed ") << i;
    }
  }
  const Eigen::VectorXd eps = q + K.completeOrthogonalDecomposition().pseudoInverse() * quadratic.A * PairProducts(q);
  EXPECT_LT((StressCoordinates(quadratic, q) - eps).norm(), 1e-10 * eps.norm());
  EXPECT_NEAR(PolynomialEnergy(K, quadratic, q), 0.5 * eps.dot(K * eps), 1e-10 * eps.dot(K * eps));
  EXPECT_GE(PolynomialEnergy(K, quadratic, q), 0.0);
}

// The in-place forms (a body's per-iteration path) give the same numbers as the returning ones,
// to the bit, and keep their storage once sized.
TEST(ReducedPolynomial, InPlaceFormsAreTheSameNumbers) {
  const Eigen::MatrixXd K = Stiffness();
  const PolynomialStiffness p = Condensed();
  PolynomialScratch s;
  Eigen::VectorXd eps, f;
  Eigen::MatrixXd T;
  for (const Eigen::Vector3d& q : {Eigen::Vector3d(1e-4, 0.02, 0.3), Eigen::Vector3d(-3e-3, -0.1, -1.0)}) {
    CondensedCoordinates(p, q, eps, s);
    EXPECT_EQ(eps, StressCoordinates(p, q));
    CondensedForce(K, p, q, eps, f, s);
    EXPECT_EQ(f, CondensedForce(K, p, q, eps));
    EXPECT_EQ(f, PolynomialForce(K, p, q));
    const double* storage = T.data();
    CondensedTangent(K, p, q, eps, T, s);
    EXPECT_EQ(T, CondensedTangent(K, p, q, eps));
    EXPECT_EQ(T, PolynomialTangent(K, p, q));
    if (storage) {
      EXPECT_EQ(T.data(), storage);
    }
  }
}

}  // namespace
}  // namespace femb
