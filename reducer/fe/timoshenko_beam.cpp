#include "reducer/fe/timoshenko_beam.h"

#include <Eigen/Geometry>
#include <cmath>

namespace femb {
namespace {

// IIE functions of one bending plane with DOFs (v1, t1, v2, t2), t ~ dv/dx, at xi in [0,1]:
// N (displacement), Nt (rotation) and their x-derivatives dN, dNt.
struct BendingShapes {
  Eigen::Vector4d N, Nt, dN, dNt;
};

BendingShapes Bending(double xi, double L, double Phi) {
  const double c = 1.0 / (1.0 + Phi), x2 = xi * xi, x3 = x2 * xi;
  BendingShapes s;
  s.N << c * (2 * x3 - 3 * x2 - Phi * xi + 1 + Phi), c * L * (x3 - (2 + Phi / 2) * x2 + (1 + Phi / 2) * xi),
      c * (-2 * x3 + 3 * x2 + Phi * xi), c * L * (x3 - (1 - Phi / 2) * x2 - (Phi / 2) * xi);
  s.dN << c * (6 * x2 - 6 * xi - Phi) / L, c * (3 * x2 - (4 + Phi) * xi + 1 + Phi / 2),
      c * (-6 * x2 + 6 * xi + Phi) / L, c * (3 * x2 - (2 - Phi) * xi - Phi / 2);
  s.Nt << c * 6 * (x2 - xi) / L, c * (3 * x2 - (4 + Phi) * xi + 1 + Phi), -c * 6 * (x2 - xi) / L,
      c * (3 * x2 - (2 - Phi) * xi);
  s.dNt << c * 6 * (2 * xi - 1) / (L * L), c * (6 * xi - 4 - Phi) / L, -c * 6 * (2 * xi - 1) / (L * L),
      c * (6 * xi - 2 + Phi) / L;
  return s;
}

// Local DOF indices of the two bending planes and the sign that turns the DOF into "t ~ dv/dx".
constexpr int kPlaneY[4] = {1, 5, 7, 11};  // (u_y, th_z): t = th_z
constexpr int kPlaneZ[4] = {2, 4, 8, 10};  // (u_z, th_y): t = -th_y
constexpr double kSignZ[4] = {1, -1, 1, -1};

// 4-point Gauss-Legendre on [0, 1]: exact for the degree-6 integrands here.
constexpr double kGaussX[4] = {0.0694318442029737, 0.3300094782075719, 0.6699905217924281, 0.9305681557970263};
constexpr double kGaussW[4] = {0.1739274225687269, 0.3260725774312731, 0.3260725774312731, 0.1739274225687269};

}  // namespace

Eigen::Matrix3d BeamFrame(const Eigen::Vector3d& x1, const Eigen::Vector3d& x2, const Eigen::Vector3d& v) {
  const Eigen::Vector3d e1 = (x2 - x1).normalized();
  const Eigen::Vector3d e3 = e1.cross(v).normalized();
  const Eigen::Vector3d e2 = e3.cross(e1);
  Eigen::Matrix3d R;
  R.row(0) = e1.transpose();
  R.row(1) = e2.transpose();
  R.row(2) = e3.transpose();
  return R;
}

Matrix12d BeamTransformation(const Eigen::Matrix3d& R) {
  Matrix12d T = Matrix12d::Zero();
  for (int b = 0; b < 4; ++b) T.block<3, 3>(3 * b, 3 * b) = R;
  return T;
}

TimoshenkoBeam::TimoshenkoBeam(double L, const MaterialSpec& material, const SectionProperties& section, bool shear)
    : L_(L), material_(material), section_(section) {
  const double G = material.E / (2.0 * (1.0 + material.nu));
  if (!shear) {
    section_.ky = section_.kz = 0.0;
  }
  if (section_.ky > 0.0) Phi_y_ = 12.0 * material.E * section_.Iz / (section_.ky * G * section_.A * L * L);
  if (section_.kz > 0.0) Phi_z_ = 12.0 * material.E * section_.Iy / (section_.kz * G * section_.A * L * L);
}

Matrix6x12d TimoshenkoBeam::LocalInterpolation(double xi) const {
  Matrix6x12d N = Matrix6x12d::Zero();
  N(0, 0) = 1.0 - xi;
  N(0, 6) = xi;
  N(3, 3) = 1.0 - xi;
  N(3, 9) = xi;
  const BendingShapes y = Bending(xi, L_, Phi_y_), z = Bending(xi, L_, Phi_z_);
  for (int a = 0; a < 4; ++a) {
    N(1, kPlaneY[a]) = y.N[a];
    N(5, kPlaneY[a]) = y.Nt[a];
    N(2, kPlaneZ[a]) = kSignZ[a] * z.N[a];
    N(4, kPlaneZ[a]) = -kSignZ[a] * z.Nt[a];  // th_y = -t
  }
  return N;
}

Eigen::Matrix<double, 6, 12> TimoshenkoBeam::StrainInterpolation(double xi) const {
  Eigen::Matrix<double, 6, 12> B = Eigen::Matrix<double, 6, 12>::Zero();
  B(0, 0) = -1.0 / L_;
  B(0, 6) = 1.0 / L_;
  B(1, 3) = -1.0 / L_;
  B(1, 9) = 1.0 / L_;
  const BendingShapes y = Bending(xi, L_, Phi_y_), z = Bending(xi, L_, Phi_z_);
  for (int a = 0; a < 4; ++a) {
    B(2, kPlaneY[a]) = y.dNt[a];           // curvature t'
    B(3, kPlaneY[a]) = y.dN[a] - y.Nt[a];  // shear v' - t
    B(4, kPlaneZ[a]) = kSignZ[a] * z.dNt[a];
    B(5, kPlaneZ[a]) = kSignZ[a] * (z.dN[a] - z.Nt[a]);
  }
  return B;
}

Eigen::Matrix<double, 6, 1> TimoshenkoBeam::SectionStiffness() const {
  const double E = material_.E, G = E / (2.0 * (1.0 + material_.nu));
  Eigen::Matrix<double, 6, 1> D;
  D << E * section_.A, G * section_.J, E * section_.Iz, section_.ky * G * section_.A, E * section_.Iy,
      section_.kz * G * section_.A;
  return D;
}

std::vector<TimoshenkoBeam::QuadraturePoint> TimoshenkoBeam::QuadraturePoints() const {
  std::vector<QuadraturePoint> points(4);
  for (int g = 0; g < 4; ++g) {
    QuadraturePoint& p = points[size_t(g)];
    p.B = StrainInterpolation(kGaussX[g]);
    p.weight = kGaussW[g] * L_;
    p.slope.setZero();
    const BendingShapes y = Bending(kGaussX[g], L_, Phi_y_), z = Bending(kGaussX[g], L_, Phi_z_);
    for (int a = 0; a < 4; ++a) {
      p.slope(0, kPlaneY[a]) = y.dN[a];              // v'
      p.slope(1, kPlaneZ[a]) = kSignZ[a] * z.dN[a];  // w'
    }
  }
  return points;
}

Matrix12d TimoshenkoBeam::LocalStiffness() const {
  const Eigen::Matrix<double, 6, 1> D = SectionStiffness();
  Matrix12d K = Matrix12d::Zero();
  for (int g = 0; g < 4; ++g) {
    const auto B = StrainInterpolation(kGaussX[g]);
    K.noalias() += (kGaussW[g] * L_) * B.transpose() * D.asDiagonal() * B;
  }
  return 0.5 * (K + K.transpose());
}

Matrix12d TimoshenkoBeam::LocalMass() const {
  const double rho = material_.rho;
  Eigen::Matrix<double, 6, 1> m;
  m << rho * section_.A, rho * section_.A, rho * section_.A, rho * section_.Ip, rho * section_.Iy, rho * section_.Iz;
  Matrix12d M = Matrix12d::Zero();
  for (int g = 0; g < 4; ++g) {
    const Matrix6x12d N = LocalInterpolation(kGaussX[g]);
    M.noalias() += (kGaussW[g] * L_) * N.transpose() * m.asDiagonal() * N;
  }
  return 0.5 * (M + M.transpose());
}

}  // namespace femb
