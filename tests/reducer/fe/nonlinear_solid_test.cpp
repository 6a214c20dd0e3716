// Geometrically nonlinear solids (St. Venant-Kirchhoff, Green-Lagrange strain): force and tangent
// against finite differences of the energy and the force; the linear stiffness at u = 0; exact
// rigid-rotation invariance; uniaxial stretch against its closed form; a slender HEX20 cantilever
// under a large tip load against the elastica (full-model Newton).
#include "reducer/fe/nonlinear_solid.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <random>

#include "reducer/mesh/gmsh_mesher.h"
#include "test_util.h"

namespace femb {
namespace {

MaterialSpec Steel(double nu = 0.3) {
  MaterialSpec m;
  m.E = 2.1e11;
  m.nu = nu;
  m.rho = 7850;
  return m;
}

// A distorted reference element (curved edges for the quadratic ones) of size ~0.1 m.
Eigen::MatrixXd Distorted(SolidType type) {
  Eigen::VectorXd N;
  Eigen::MatrixXd dN;
  const int n = SolidNodeCount(type);
  // Reference node coordinates: the candidate point where the node's own shape function is 1.
  Eigen::MatrixXd X(n, 3);
  const bool tet = type == SolidType::kTet4 || type == SolidType::kTet10;
  std::vector<Eigen::Vector3d> candidates;
  const std::vector<double> c = tet ? std::vector<double>{0, 0.5, 1} : std::vector<double>{-1, 0, 1};
  for (double x : c)
    for (double y : c)
      for (double z : c) candidates.emplace_back(x, y, z);
  for (int a = 0; a < n; ++a) {
    for (const Eigen::Vector3d& p : candidates) {
      SolidShapeFunctions(type, p, &N, &dN);
      if (std::abs(N[a] - 1) < 1e-12) {
        X.row(a) = p.transpose();
        break;
      }
    }
  }
  for (int a = 0; a < n; ++a) {
    const Eigen::Vector3d p = X.row(a).transpose();
    X.row(a) = 0.05 * Eigen::Vector3d(p.x() + 0.1 * p.y() * p.y(), 1.2 * p.y() + 0.1 * p.z(),
                                      0.9 * p.z() + 0.05 * p.x() * p.x())
                          .transpose();
  }
  return X;
}

class NonlinearElement : public ::testing::TestWithParam<SolidType> {};

TEST_P(NonlinearElement, ForceIsTheEnergyGradientAndTangentTheForceDerivative) {
  const SolidType type = GetParam();
  const Eigen::MatrixXd X = Distorted(type);
  const int n = 3 * SolidNodeCount(type);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1, 1);
  Eigen::VectorXd u(n);
  for (int i = 0; i < n; ++i) u[i] = 0.01 * unit(rng);  // displacement gradients ~ 0.2: nonlinear
  const NonlinearElementState s = SvkSolidElement(type, X, Steel(), u, true);
  const double h = 1e-7;
  Eigen::VectorXd grad(n);
  Eigen::MatrixXd dforce(n, n);
  for (int i = 0; i < n; ++i) {
    Eigen::VectorXd up = u, um = u;
    up[i] += h;
    um[i] -= h;
    const NonlinearElementState p = SvkSolidElement(type, X, Steel(), up, false);
    const NonlinearElementState m = SvkSolidElement(type, X, Steel(), um, false);
    grad[i] = (p.energy - m.energy) / (2 * h);
    dforce.col(i) = (p.force - m.force) / (2 * h);
  }
  const double f_err = (grad - s.force).norm() / s.force.norm();
  const double k_err = (dforce - s.tangent).norm() / s.tangent.norm();
  std::printf("[ info ] %s: force vs energy FD %.2e, tangent vs force FD %.2e\n", SolidTypeName(type).c_str(), f_err,
              k_err);
  EXPECT_LT(f_err, 1e-6);
  EXPECT_LT(k_err, 1e-6);
}

TEST_P(NonlinearElement, TangentAtZeroIsTheLinearStiffness) {
  const SolidType type = GetParam();
  const Eigen::MatrixXd X = Distorted(type);
  const NonlinearElementState s =
      SvkSolidElement(type, X, Steel(), Eigen::VectorXd::Zero(3 * SolidNodeCount(type)), true);
  const Eigen::MatrixXd K = ComputeSolidElement(type, X, Steel(), 1).K;
  EXPECT_LT((s.tangent - K).norm(), 1e-12 * K.norm());
  EXPECT_EQ(s.force.norm(), 0.0);
}

TEST_P(NonlinearElement, LargeRigidRotationCostsNothing) {
  // u = (R - 1) X for a 70 degree rotation: Green-Lagrange strain is exactly zero.
  const SolidType type = GetParam();
  const Eigen::MatrixXd X = Distorted(type);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(1.2, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  Eigen::VectorXd u(3 * X.rows());
  for (long a = 0; a < X.rows(); ++a) u.segment<3>(3 * a) = (R - Eigen::Matrix3d::Identity()) * X.row(a).transpose();
  const NonlinearElementState s = SvkSolidElement(type, X, Steel(), u, false);
  const double scale = 2.1e11 * 0.05 * 0.05;  // E times a face area: a force scale
  EXPECT_LT(s.force.norm(), 1e-10 * scale);
  EXPECT_LT(std::abs(s.energy), 1e-10 * scale * 0.05);
}

INSTANTIATE_TEST_SUITE_P(Types, NonlinearElement,
                         ::testing::Values(SolidType::kTet4, SolidType::kTet10, SolidType::kHex8, SolidType::kHex20),
                         [](const auto& test) { return SolidTypeName(test.param); });

TEST(NonlinearSolid, UniaxialStretchMatchesTheClosedForm) {
  // Unit cube (HEX8), nu = 0, u_x = (lambda - 1) X: S_xx = E (lambda^2 - 1) / 2, first Piola-
  // Kirchhoff P_xx = lambda S_xx; the nodal forces on the face x = 1 add up to P_xx times its area.
  Eigen::MatrixXd X(8, 3);
  X << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1;
  for (double lambda : {0.6, 1.5, 2.0}) {
    Eigen::VectorXd u = Eigen::VectorXd::Zero(24);
    for (int a = 0; a < 8; ++a) u[3 * a] = (lambda - 1) * X(a, 0);
    const NonlinearElementState s = SvkSolidElement(SolidType::kHex8, X, Steel(0.0), u, false);
    double face = 0;
    for (int a = 0; a < 8; ++a)
      if (X(a, 0) == 1) face += s.force[3 * a];
    const double expected = lambda * 2.1e11 * (lambda * lambda - 1) / 2;
    EXPECT_NEAR(face, expected, 1e-12 * std::abs(expected)) << lambda;
    EXPECT_NEAR(s.energy, 2.1e11 * std::pow((lambda * lambda - 1) / 2, 2) / 2, 1e-3);
  }
}

TEST(NonlinearSolid, SlenderCantileverMatchesTheElasticaUnderALargeTipLoad) {
  // Box 1 x 0.05 x 0.05 m in structured HEX20 (40 x 2 x 2), nu = 0, clamped face x = 0, a tip
  // force P (equal nodal forces on the face x = 1) staying along -z, P L^2 / EI = 3 in 10 load
  // steps of Newton on the full model. Reference: the elastica of an inextensible Euler-Bernoulli
  // beam; shear (0.15% of the deflection at L/h = 20) and the 3D end regions make up the rest.
  // Tolerance: 1% of the tip displacement at every load step.
  MeshRequest request;
  request.shape = SolidShape::kBox;
  request.size = Eigen::Vector3d(1.0, 0.05, 0.05);
  request.element_size = 0.025;
  request.order = 2;
  request.hexahedra = true;
  const SolidMesh mesh = MeshWithGmsh(request);
  const MaterialSpec material = Steel(0.0);
  const SvkSolidMesh solid(mesh.type, mesh.nodes, mesh.cells, material);
  const double EI = 2.1e11 * 0.05 * std::pow(0.05, 3) / 12, L = 1.0, P = 3 * EI / (L * L);
  std::vector<int> fixed;
  for (int node : mesh.node_sets.at("xmin"))
    for (int d = 0; d < 3; ++d) fixed.push_back(3 * node + d);
  const std::vector<int>& tip = mesh.node_sets.at("xmax");
  Eigen::VectorXd f = Eigen::VectorXd::Zero(solid.n_dofs());
  for (int node : tip) f[3 * node + 2] = -P / double(tip.size());
  const NonlinearStaticResult r =
      SolveNonlinearStatic(solid, SparseMatrix(), fixed, Eigen::VectorXd::Zero(long(fixed.size())), f, 10);
  ASSERT_TRUE(r.converged) << r.message;
  std::printf("[ info ]  P L^2/EI  iterations  femb (du, w)/L       elastica (du, w)/L   error\n");
  for (size_t s = 0; s < r.u.size(); ++s) {
    Eigen::Vector2d femb(0, 0);
    for (int node : tip) femb += Eigen::Vector2d(-r.u[s][3 * node], -r.u[s][3 * node + 2]) / double(tip.size());
    const Eigen::Vector2d ref = test::ElasticaTip(r.load_factor[s] * P, EI, L);
    const double err = (femb - ref).norm() / ref.norm();
    std::printf("[ info ]  %7.2f  %6d      (%.4f, %.4f)     (%.4f, %.4f)     %.3f%%\n", 3 * r.load_factor[s],
                r.iterations[s], femb.x(), femb.y(), ref.x(), ref.y(), 100 * err);
    EXPECT_LT(err, 0.01) << "at P L^2/EI = " << 3 * r.load_factor[s];
  }
}

}  // namespace
}  // namespace femb
