// Solid elements: quadrature exactness, shape-function identities, rigid-body modes, the
// patch test (a linear displacement field costs exactly V eps^T D eps / 2 on distorted
// elements), mass and volume, and a clear error for an inverted element.
#include "reducer/fe/solid_element.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>
#include <tuple>

#include "test_util.h"

namespace femb {
namespace {

const SolidType kTypes[4] = {SolidType::kTet4, SolidType::kTet10, SolidType::kHex8, SolidType::kHex20};

// Reference node coordinates in gmsh order.
Eigen::MatrixXd ReferenceNodes(SolidType type) {
  const int n = SolidNodeCount(type);
  Eigen::MatrixXd X(n, 3);
  if (type == SolidType::kTet4 || type == SolidType::kTet10) {
    X.topRows(4) << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
    const int edges[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {2, 3}, {1, 3}};
    for (int e = 0; e < 6 && n == 10; ++e) X.row(4 + e) = 0.5 * (X.row(edges[e][0]) + X.row(edges[e][1]));
  } else {
    X.topRows(8) << -1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1, -1, -1, 1, 1, -1, 1, 1, 1, 1, -1, 1, 1;
    const int edges[12][2] = {{0, 1}, {0, 3}, {0, 4}, {1, 2}, {1, 5}, {2, 3},
                              {2, 6}, {3, 7}, {4, 5}, {4, 7}, {5, 6}, {6, 7}};
    for (int e = 0; e < 12 && n == 20; ++e) X.row(8 + e) = 0.5 * (X.row(edges[e][0]) + X.row(edges[e][1]));
  }
  return X;
}

// A distorted element: an affine map of the reference element plus (for straight-edged
// patch tests) nothing else, or small random node perturbations (curved elements).
Eigen::MatrixXd Distorted(SolidType type, bool perturb) {
  Eigen::Matrix3d A;
  A << 1.2, 0.3, -0.1, 0.1, 0.9, 0.2, -0.2, 0.1, 1.1;
  Eigen::MatrixXd X = (ReferenceNodes(type) * A.transpose()).rowwise() + Eigen::RowVector3d(0.5, -0.3, 2.0);
  if (perturb) {
    std::mt19937 rng(4);
    std::uniform_real_distribution<double> u(-0.05, 0.05);
    for (int i = 0; i < X.rows(); ++i)
      for (int d = 0; d < 3; ++d) X(i, d) += u(rng);
  }
  return X;
}

const MaterialSpec kSteel{2.1e11, 0.3, 7850};

TEST(SolidElement, TetrahedronQuadratureIsExactToItsDegree) {
  // TET10: 14 points, degree 5; TET4: 4 points, degree 2 (exact monomial integrals over the
  // reference tetrahedron: a! b! c! / (a + b + c + 3)!).
  for (const auto& [type, degree, count] : {std::tuple{SolidType::kTet10, 5, 14}, std::tuple{SolidType::kTet4, 2, 4}}) {
    std::vector<Eigen::Vector3d> p;
    std::vector<double> w;
    SolidQuadrature(type, &p, &w);
    EXPECT_EQ(int(p.size()), count);
    auto factorial = [](int k) {
      double f = 1;
      for (int i = 2; i <= k; ++i) f *= i;
      return f;
    };
    for (int a = 0; a <= degree; ++a)
      for (int b = 0; a + b <= degree; ++b)
        for (int c = 0; a + b + c <= degree; ++c) {
          double sum = 0;
          for (size_t q = 0; q < p.size(); ++q)
            sum += w[q] * std::pow(p[q].x(), a) * std::pow(p[q].y(), b) * std::pow(p[q].z(), c);
          const double exact = factorial(a) * factorial(b) * factorial(c) / factorial(a + b + c + 3);
          EXPECT_NEAR(sum, exact, 1e-14) << SolidTypeName(type) << " " << a << b << c;
        }
  }
}

TEST(SolidElement, ShapeFunctionsInterpolateAndSumToOne) {
  for (SolidType type : kTypes) {
    const Eigen::MatrixXd X = ReferenceNodes(type);
    Eigen::VectorXd N;
    Eigen::MatrixXd dN;
    for (int i = 0; i < X.rows(); ++i) {
      SolidShapeFunctions(type, X.row(i).transpose(), &N, &dN);
      EXPECT_LT((N - Eigen::VectorXd::Unit(X.rows(), i)).norm(), 1e-14) << SolidTypeName(type) << " node " << i;
    }
    SolidShapeFunctions(type, Eigen::Vector3d(0.2, 0.1, 0.3), &N, &dN);
    EXPECT_NEAR(N.sum(), 1.0, 1e-14);
    EXPECT_LT(dN.colwise().sum().norm(), 1e-14);
    // Derivatives against central differences.
    Eigen::VectorXd Np, Nm;
    Eigen::MatrixXd unused;
    for (int d = 0; d < 3; ++d) {
      Eigen::Vector3d h = Eigen::Vector3d::Zero();
      h[d] = 1e-6;
      SolidShapeFunctions(type, Eigen::Vector3d(0.2, 0.1, 0.3) + h, &Np, &unused);
      SolidShapeFunctions(type, Eigen::Vector3d(0.2, 0.1, 0.3) - h, &Nm, &unused);
      EXPECT_LT(((Np - Nm) / 2e-6 - dN.col(d)).norm(), 1e-8) << SolidTypeName(type);
    }
  }
}

TEST(SolidElement, RigidModesPatchTestMassAndVolume) {
  for (SolidType type : kTypes) {
    SCOPED_TRACE(SolidTypeName(type));
    for (bool perturb : {false, true}) {
      if (perturb && (type == SolidType::kTet4 || type == SolidType::kHex8)) continue;  // straight edges only
      const Eigen::MatrixXd X = Distorted(type, perturb);
      const SolidElementMatrices e = ComputeSolidElement(type, X, kSteel, 7);
      const int n = int(X.rows());
      // Six rigid-body modes, the rest positive.
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(e.K);
      const double top = eig.eigenvalues().maxCoeff();
      int zero = 0;
      for (int i = 0; i < 3 * n; ++i) zero += std::abs(eig.eigenvalues()[i]) < 1e-10 * top;
      EXPECT_EQ(zero, 6);
      EXPECT_GT(eig.eigenvalues()[6], 1e-8 * top);
      // Patch test: u = A x + b gives constant strain eps = sym(A); energy V eps^T D eps / 2.
      Eigen::Matrix3d A;
      A << 1e-3, 2e-4, -1e-4, 3e-4, -5e-4, 6e-4, -2e-4, 1e-4, 8e-4;
      Eigen::VectorXd u(3 * n);
      for (int a = 0; a < n; ++a) u.segment<3>(3 * a) = A * X.row(a).transpose() + Eigen::Vector3d(1, 2, 3) * 1e-3;
      Eigen::Matrix<double, 6, 1> eps;
      eps << A(0, 0), A(1, 1), A(2, 2), A(1, 2) + A(2, 1), A(0, 2) + A(2, 0), A(0, 1) + A(1, 0);
      const double exact = 0.5 * e.volume * eps.dot(IsotropicElasticity(kSteel.E, kSteel.nu) * eps);
      EXPECT_NEAR(0.5 * u.dot(e.K * u), exact, 1e-10 * exact);
      // Mass: rho V in each direction.
      Eigen::VectorXd ones_x = Eigen::VectorXd::Zero(3 * n);
      for (int a = 0; a < n; ++a) ones_x[3 * a] = 1;
      EXPECT_NEAR(ones_x.dot(e.M * ones_x), kSteel.rho * e.volume, 1e-12 * kSteel.rho * e.volume);
      if (!perturb) {
        // Affine image of the reference element: volume = |det A| V_ref.
        Eigen::Matrix3d Am;
        Am << 1.2, 0.3, -0.1, 0.1, 0.9, 0.2, -0.2, 0.1, 1.1;
        const double v_ref = (type == SolidType::kTet4 || type == SolidType::kTet10) ? 1.0 / 6.0 : 8.0;
        EXPECT_NEAR(e.volume, Am.determinant() * v_ref, 1e-13);
      }
    }
  }
}

TEST(SolidElement, InvertedElementIsNamed) {
  Eigen::MatrixXd X = ReferenceNodes(SolidType::kTet4);
  X.row(3) = Eigen::RowVector3d(0, 0, -1);  // the fourth vertex below the base: negative volume
  const std::string message = test::ThrownMessage([&] { ComputeSolidElement(SolidType::kTet4, X, kSteel, 42); });
  EXPECT_NE(message.find("element 42 (tet4): inverted or degenerate"), std::string::npos) << message;
  X.row(3) = Eigen::RowVector3d(0.3, 0.3, 0);  // flat
  EXPECT_NE(test::ThrownMessage([&] { ComputeSolidElement(SolidType::kTet4, X, kSteel, 43); }).find("element 43"),
            std::string::npos);
}

}  // namespace
}  // namespace femb
