#include "reducer/fe/solid_element.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "formats/input_error.h"

namespace femb {
namespace {

// Gauss-Legendre on [-1, 1].
void GaussLegendre(int n, std::vector<double>* x, std::vector<double>* w) {
  switch (n) {
    case 2:
      *x = {-0.5773502691896257, 0.5773502691896257};
      *w = {1.0, 1.0};
      break;
    case 3:
      *x = {-0.7745966692414834, 0.0, 0.7745966692414834};
      *w = {0.5555555555555556, 0.8888888888888888, 0.5555555555555556};
      break;
    default:
      *x = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
      *w = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};
      break;
  }
}

}  // namespace

void SolidQuadrature(SolidType type, std::vector<Eigen::Vector3d>* points, std::vector<double>* weights) {
  points->clear();
  weights->clear();
  std::vector<double> x, w;
  if (type == SolidType::kHex8 || type == SolidType::kHex20) {
    GaussLegendre(type == SolidType::kHex8 ? 2 : 3, &x, &w);
    for (size_t i = 0; i < x.size(); ++i)
      for (size_t j = 0; j < x.size(); ++j)
        for (size_t k = 0; k < x.size(); ++k) {
          points->emplace_back(x[i], x[j], x[k]);
          weights->push_back(w[i] * w[j] * w[k]);
        }
    return;
  }
  // Symmetric tetrahedron rules in barycentric coordinates (weights sum to the volume 1/6).
  // Each orbit: a barycentric point and all its distinct permutations.
  auto orbit = [&](const std::array<double, 4>& l, double weight) {
    std::array<double, 4> p = l;
    std::sort(p.begin(), p.end());
    do {
      points->emplace_back(p[1], p[2], p[3]);
      weights->push_back(weight / 6);
    } while (std::next_permutation(p.begin(), p.end()));
  };
  if (type == SolidType::kTet4) {
    // 4 points, degree 2: exact for the consistent mass of linear shape functions.
    const double a = (5 - std::sqrt(5.0)) / 20;
    orbit({a, a, a, 1 - 3 * a}, 0.25);
    return;
  }
  // 14 points, degree 5, positive weights (Walkington; Jaskowiec & Sukumar): exact for the
  // quadratic-shape-function mass (degree 4) and the stiffness of straight-sided TET10.
  const double a1 = 0.31088591926330060980, a2 = 0.092735250310891226402, b = 0.045503704125649649492;
  orbit({a1, a1, a1, 1 - 3 * a1}, 0.11268792571801585080);
  orbit({a2, a2, a2, 1 - 3 * a2}, 0.073493043116361949544);
  orbit({b, b, 0.5 - b, 0.5 - b}, 0.042546020777081466438);
}

Eigen::Matrix<double, 6, 6> IsotropicElasticity(double E, double nu) {
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
  Eigen::Matrix<double, 6, 6> D = Eigen::Matrix<double, 6, 6>::Zero();
  D.topLeftCorner<3, 3>().setConstant(lambda);
  D.topLeftCorner<3, 3>().diagonal().array() += 2 * mu;
  D.bottomRightCorner<3, 3>().diagonal().setConstant(mu);
  return D;
}

std::vector<SolidPoint> SolidElementPoints(SolidType type, const Eigen::MatrixXd& X, long element_id) {
  std::vector<Eigen::Vector3d> points;
  std::vector<double> weights;
  SolidQuadrature(type, &points, &weights);
  Eigen::MatrixXd dN;
  // Scale for the degeneracy test: det J relative to the element's size cubed.
  const double size = (X.rowwise() - X.colwise().mean()).rowwise().norm().maxCoeff();
  std::vector<SolidPoint> out(points.size());
  for (size_t q = 0; q < points.size(); ++q) {
    SolidShapeFunctions(type, points[q], &out[q].N, &dN);
    const Eigen::Matrix3d J = X.transpose() * dN;  // dx/dxi
    const double det = J.determinant();
    if (!(det > 1e-10 * size * size * size)) {
      char buffer[200];
      std::snprintf(buffer, sizeof buffer,
                    "element %ld (%s): inverted or degenerate (det J = %.3g at a quadrature point)", element_id,
                    SolidTypeName(type).c_str(), det);
      throw InputError(buffer);
    }
    out[q].dNdX = dN * J.inverse();
    out[q].dV = det * weights[q];
  }
  return out;
}

Eigen::MatrixXd SolidStrainMatrix(const Eigen::MatrixXd& dNdX) {
  const long n = dNdX.rows();
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(6, 3 * n);
  for (long a = 0; a < n; ++a) {
    const double gx = dNdX(a, 0), gy = dNdX(a, 1), gz = dNdX(a, 2);
    B(0, 3 * a) = gx;
    B(1, 3 * a + 1) = gy;
    B(2, 3 * a + 2) = gz;
    B(3, 3 * a + 1) = gz;
    B(3, 3 * a + 2) = gy;
    B(4, 3 * a) = gz;
    B(4, 3 * a + 2) = gx;
    B(5, 3 * a) = gy;
    B(5, 3 * a + 1) = gx;
  }
  return B;
}

SolidElementMatrices ComputeSolidElement(SolidType type, const Eigen::MatrixXd& X, const MaterialSpec& material,
                                         long element_id) {
  const int n = SolidNodeCount(type);
  SolidElementMatrices out;
  out.K = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  out.M = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  const Eigen::Matrix<double, 6, 6> D = IsotropicElasticity(material.E, material.nu);
  for (const SolidPoint& p : SolidElementPoints(type, X, element_id)) {
    const Eigen::VectorXd& N = p.N;
    const Eigen::MatrixXd B = SolidStrainMatrix(p.dNdX);
    const double dV = p.dV;
    out.volume += dV;
    out.K.noalias() += dV * B.transpose() * D * B;
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) {
        const double m = material.rho * N[a] * N[b] * dV;
        for (int d = 0; d < 3; ++d) out.M(3 * a + d, 3 * b + d) += m;
      }
  }
  out.K = 0.5 * (out.K + out.K.transpose()).eval();
  return out;
}

}  // namespace femb
