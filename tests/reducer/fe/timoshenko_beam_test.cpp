// The Timoshenko beam element against closed forms: Przemieniecki's exact end-loaded stiffness
// (Theory of Matrix Structural Analysis, 1968, eq. 5.116 with shear parameter Phi), the
// Euler-Bernoulli consistent mass with rotary inertia (Hermite cubics), rigid-body invariance.
#include "reducer/fe/timoshenko_beam.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

namespace femb {
namespace {

constexpr double kL = 0.12;  // stubby: shear parameter Phi_y = 0.085

MaterialSpec Steel() { return {2.1e11, 0.3, 7850.0}; }

SectionProperties Rect() {
  BeamSectionSpec s;
  s.shape = SectionShape::kRectangle;
  s.width = 0.02;
  s.height = 0.05;
  return ComputeSectionProperties(s, 0.3);
}

// Bending block of plane x-y (DOFs v1, th1, v2, th2).
Eigen::Matrix4d ClosedFormBending(double EI, double L, double Phi) {
  Eigen::Matrix4d K;
  K << 12, 6 * L, -12, 6 * L, 6 * L, (4 + Phi) * L * L, -6 * L, (2 - Phi) * L * L, -12, -6 * L, 12, -6 * L, 6 * L,
      (2 - Phi) * L * L, -6 * L, (4 + Phi) * L * L;
  return EI / ((1 + Phi) * L * L * L) * K;
}

Eigen::Matrix4d Pick(const Matrix12d& A, const int idx[4]) {
  Eigen::Matrix4d out;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) out(i, j) = A(idx[i], idx[j]);
  return out;
}

TEST(TimoshenkoBeam, BendingStiffnessMatchesClosedFormWithShear) {
  const SectionProperties s = Rect();
  TimoshenkoBeam beam(kL, Steel(), s, /*shear=*/true);
  ASSERT_GT(beam.Phi_y(), 0.01);  // a stubby element: shear matters
  const Matrix12d K = beam.LocalStiffness();
  const int plane_y[4] = {1, 5, 7, 11};
  const Eigen::Matrix4d Ky = ClosedFormBending(Steel().E * s.Iz, kL, beam.Phi_y());
  EXPECT_LT((Pick(K, plane_y) - Ky).norm(), 1e-12 * Ky.norm());
  // Plane x-z: same matrix for (w, -th_y).
  const int plane_z[4] = {2, 4, 8, 10};
  Eigen::Matrix4d Kz = ClosedFormBending(Steel().E * s.Iy, kL, beam.Phi_z());
  const Eigen::Vector4d sign(1, -1, 1, -1);
  Kz = sign.asDiagonal() * Kz * sign.asDiagonal();
  EXPECT_LT((Pick(K, plane_z) - Kz).norm(), 1e-12 * Kz.norm());
  // Axial and torsion.
  const double G = Steel().E / 2.6;
  EXPECT_NEAR(K(0, 0), Steel().E * s.A / kL, 1e-12 * K(0, 0));
  EXPECT_NEAR(K(0, 6), -Steel().E * s.A / kL, 1e-12 * K(0, 0));
  EXPECT_NEAR(K(3, 3), G * s.J / kL, 1e-12 * K(3, 3));
}

TEST(TimoshenkoBeam, EulerBernoulliMassIsHermiteConsistentMassWithRotaryInertia) {
  const SectionProperties s = Rect();
  const MaterialSpec m = Steel();
  TimoshenkoBeam beam(kL, m, s, /*shear=*/false);
  EXPECT_EQ(beam.Phi_y(), 0.0);
  const double L = kL;
  Eigen::Matrix4d translational, rotary;
  translational << 156, 22 * L, 54, -13 * L, 22 * L, 4 * L * L, 13 * L, -3 * L * L, 54, 13 * L, 156, -22 * L, -13 * L,
      -3 * L * L, -22 * L, 4 * L * L;
  rotary << 36, 3 * L, -36, 3 * L, 3 * L, 4 * L * L, -3 * L, -L * L, -36, -3 * L, 36, -3 * L, 3 * L, -L * L, -3 * L,
      4 * L * L;
  const Eigen::Matrix4d expected = m.rho * s.A * L / 420.0 * translational + m.rho * s.Iz / (30.0 * L) * rotary;
  const int plane_y[4] = {1, 5, 7, 11};
  const Matrix12d M = beam.LocalMass();
  EXPECT_LT((Pick(M, plane_y) - expected).norm(), 1e-12 * expected.norm());
  // Axial: rho A L / 6 [2 1; 1 2]; torsion with the polar moment.
  EXPECT_NEAR(M(0, 0), m.rho * s.A * L / 3.0, 1e-14);
  EXPECT_NEAR(M(0, 6), m.rho * s.A * L / 6.0, 1e-14);
  EXPECT_NEAR(M(3, 3), m.rho * s.Ip * L / 3.0, 1e-16);
}

TEST(TimoshenkoBeam, RigidMotionsCostNoEnergyInAnyOrientation) {
  const Eigen::Vector3d x1(0.1, -0.2, 0.3), x2(0.4, 0.5, -0.1);
  const Eigen::Matrix3d R = BeamFrame(x1, x2, Eigen::Vector3d(0.2, 1.0, 0.3));
  EXPECT_LT((R * R.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-14);
  TimoshenkoBeam beam((x2 - x1).norm(), Steel(), Rect(), true);
  const Matrix12d T = BeamTransformation(R);
  const Matrix12d K = T.transpose() * beam.LocalStiffness() * T;
  // Six rigid motions in global DOFs: translations, and rotations about the origin.
  Eigen::Matrix<double, 12, 6> rigid = Eigen::Matrix<double, 12, 6>::Zero();
  for (int node = 0; node < 2; ++node) {
    const Eigen::Vector3d x = node == 0 ? x1 : x2;
    rigid.block<3, 3>(6 * node, 0).setIdentity();
    rigid.block<3, 3>(6 * node + 3, 3).setIdentity();
    Eigen::Matrix3d skew;
    skew << 0, -x.z(), x.y(), x.z(), 0, -x.x(), -x.y(), x.x(), 0;
    rigid.block<3, 3>(6 * node, 3) = -skew;
  }
  EXPECT_LT((K * rigid).norm(), 1e-9 * K.norm());
}

TEST(TimoshenkoBeam, InterpolationReproducesNodesAndHasConstantShearStrain) {
  TimoshenkoBeam beam(kL, Steel(), Rect(), true);
  Matrix6x12d N0 = beam.LocalInterpolation(0.0), N1 = beam.LocalInterpolation(1.0);
  Matrix6x12d node0 = Matrix6x12d::Zero(), node1 = Matrix6x12d::Zero();
  node0.leftCols(6).setIdentity();
  node1.rightCols(6).setIdentity();
  EXPECT_LT((N0 - node0).norm(), 1e-14);
  EXPECT_LT((N1 - node1).norm(), 1e-14);
  // An end-loaded cantilever (v1 = th1 = 0, tip load P) has exact tip values; the IIE field
  // must then match the exact Timoshenko deflection at midspan:
  // v(x) = P/(EI) (L x^2/2 - x^3/6) + P x/(kGA).
  const SectionProperties s = Rect();
  const double E = Steel().E, G = E / 2.6, P = 1000.0, EI = E * s.Iz, kGA = s.ky * G * s.A;
  auto v = [&](double x) { return P / EI * (kL * x * x / 2 - x * x * x / 6) + P * x / kGA; };
  auto th = [&](double x) { return P / EI * (kL * x - x * x / 2); };
  Eigen::Matrix<double, 12, 1> d = Eigen::Matrix<double, 12, 1>::Zero();
  d[7] = v(kL);
  d[11] = th(kL);
  const Eigen::Matrix<double, 6, 1> mid = beam.LocalInterpolation(0.5) * d;
  EXPECT_NEAR(mid[1], v(0.5 * kL), 1e-12 * v(kL));
  EXPECT_NEAR(mid[5], th(0.5 * kL), 1e-12 * th(kL));
}

TEST(BeamSection, NamedShapes) {
  BeamSectionSpec tube;
  tube.shape = SectionShape::kTube;
  tube.outer_radius = 0.01;
  tube.wall = 0.001;
  const SectionProperties t = ComputeSectionProperties(tube, 0.3);
  EXPECT_NEAR(t.A, M_PI * (1e-4 - 0.81e-4), 1e-15);
  EXPECT_NEAR(t.Iy, M_PI / 4 * (1e-8 - std::pow(0.009, 4)), 1e-20);
  EXPECT_NEAR(t.J, 2 * t.Iy, 1e-20);
  // Thin-walled limit of Cowper's factor: 2(1+nu)/(4+3nu) = 0.5306 for nu = 0.3; a 10% wall is close.
  EXPECT_NEAR(t.ky, 0.53, 0.01);
  BeamSectionSpec sq;
  sq.shape = SectionShape::kRectangle;
  sq.width = sq.height = 0.01;
  // Square torsion constant 0.1406 a^4 (Roark).
  EXPECT_NEAR(ComputeSectionProperties(sq, 0.3).J / 1e-8, 0.1406, 0.0005);
}

}  // namespace
}  // namespace femb
