// Modal stresses: the stress of a reduced static solution, sum_i q_i sigma_i, against
// beam theory; rigid-body motions cause none; the superelement file keeps them.
#include "reducer/reduction/modal_stress.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>

#include "formats/superelement_checks.h"
#include "formats/superelement_file.h"
#include "reducer/fe/solid_model.h"
#include "test_util.h"

namespace femb {
namespace {

// A cantilever bar 1 m x 50 mm x 50 mm along x, interfaces root (x = 0) and tip (x = 1).
std::string SolidBar(const std::string& elements, double size) {
  return "name: bar\ntype: solid\nmaterial: {E: 2.1e11, nu: 0.3, rho: 7850}\n"
         "geometry: {shape: box, size: [1.0, 0.05, 0.05]}\n"
         "mesh: {size: " +
         std::to_string(size) + ", order: 2, elements: " + elements +
         "}\n"
         "interfaces: [{name: root, group: xmin}, {name: tip, group: xmax}]\n"
         "reduction: {internal_modes: 4}\n";
}

// The reduced static solution with the first interface clamped and the load on the second.
Eigen::VectorXd ClampedSolution(const Superelement& se, const Eigen::Matrix<double, 6, 1>& tip_load) {
  const int n = se.n_reduced_dofs();
  Eigen::VectorXd f = Eigen::VectorXd::Zero(n - 6);
  f.head<6>() = tip_load;
  Eigen::VectorXd q = Eigen::VectorXd::Zero(n);
  q.tail(n - 6) = se.K.bottomRightCorner(n - 6, n - 6).ldlt().solve(f);
  return q;
}

// The stress (6 components) of the solution q at point p.
Eigen::Matrix<double, 6, 1> StressAt(const ModalStress& s, int p, const Eigen::VectorXd& q) {
  return s.modes.middleRows(6 * p, 6).cast<double>() * q;
}

int NearestPoint(const ModalStress& s, const Eigen::Vector3d& x) {
  int best = 0;
  for (int p = 1; p < s.n_points(); ++p)
    if ((s.points.row(p).transpose() - x).norm() < (s.points.row(best).transpose() - x).norm()) best = p;
  return best;
}

// Reference: Euler-Bernoulli beam theory, sigma_xx = M c / I with M = F (L - x) of a tip force F
// along y; the RBE2 couplings at the ends disturb the field only near them (Saint-Venant), so the
// stations x = 0.25 ... 0.75 see the beam's stress. Tolerance 2%, measured 1e-6 on
// HEX20 (quadratic elements represent the linear bending stress exactly) and 0.2% on TET10.
void ExpectBendingStress(const Superelement& se, double tolerance) {
  ASSERT_TRUE(se.stress.has_value());
  const ModalStress& s = *se.stress;
  EXPECT_EQ(s.method, "solid_nodal_l2");
  const double F = 1000, L = 1.0, I = 0.05 * std::pow(0.05, 3) / 12;
  Eigen::Matrix<double, 6, 1> load = Eigen::Matrix<double, 6, 1>::Zero();
  load[1] = F;
  const Eigen::VectorXd q = ClampedSolution(se, load);
  for (double x : {0.25, 0.5, 0.75}) {
    for (double y : {0.0, 0.05}) {
      const int p = NearestPoint(s, Eigen::Vector3d(x, y, 0.025));
      const double c = s.points(p, 1) - 0.025, M = F * (L - s.points(p, 0));
      const double reference = -M * c / I;  // a tip force along +y compresses the +y side
      const Eigen::Matrix<double, 6, 1> sigma = StressAt(s, p, q);
      EXPECT_NEAR(sigma[0], reference, tolerance * std::abs(reference)) << "x = " << x << ", y = " << y;
      // The other components (zero in beam theory at the surface; the mesh's nodal shear there is
      // the smeared parabola of the transverse shear) below 1% of the largest bending stress.
      EXPECT_LT(sigma.tail<5>().cwiseAbs().maxCoeff(), 0.01 * F * L * 0.025 / I);
    }
  }
}

TEST(ModalStress, SolidCantileverBendingStressIsBeamTheoryHex20) {
  ExpectBendingStress(test::Reduce(SolidBar("hexahedra", 0.025)), 1e-4);
}

TEST(ModalStress, SolidCantileverBendingStressIsBeamTheoryTet10) {
  ExpectBendingStress(test::Reduce(SolidBar("tetrahedra", 0.0125)), 0.02);
}

TEST(ModalStress, RigidBodyMotionsCauseNoStress) {
  // Phi_rig0's six rigid motions (about the frame origin) against the stress of one interface
  // coordinate: zero to the single precision of the stored modes.
  for (const Superelement& se :
       {test::Reduce(SolidBar("hexahedra", 0.025)),
        test::Reduce(test::StraightBeamYaml(1.0, 10, "{shape: rectangle, width: 0.02, height: 0.04}",
                                            "{E: 2.1e11, nu: 0.3, rho: 7850}", "[{name: A}, {name: B}]"))}) {
    ASSERT_TRUE(se.stress.has_value());
    const Eigen::MatrixXd Phi_rig0 = RigidBodyModes(se, se.floating_frame.origin);
    const Eigen::MatrixXd modes = se.stress->modes.cast<double>();
    const double scale = modes.cwiseAbs().maxCoeff() * Phi_rig0.cwiseAbs().maxCoeff();
    EXPECT_LT((modes * Phi_rig0).cwiseAbs().maxCoeff(), 1e-5 * scale) << se.stress->method;
    // The file check sees it, and a stress dataset that does not belong to the basis fails it.
    const SuperelementChecks good = CheckSuperelement(se);
    ASSERT_TRUE(good.all_ok()) << good.first_failure()->detail;
    Superelement bad = se;
    bad.stress->modes.col(0) += bad.stress->modes.col(1);
    const SuperelementChecks checks = CheckSuperelement(bad);
    ASSERT_NE(checks.first_failure(), nullptr);
    EXPECT_EQ(checks.first_failure()->name, "stress_rigid_body");
  }
}

TEST(ModalStress, BeamFibreStressesAreBeamTheoryExactly) {
  // A rectangle 20 mm (y) x 40 mm (z) cantilever, 1 m, clamped at A; tip loads N = 1 kN,
  // F_y = 100 N, F_z = -100 N, T = 10 N m. Section forces at x = 0.5 and the fibre stresses there
  // against sigma = N / A + M_y z / I_y - M_z y / I_z, Jourawski 3 V / 2 A and Saint-Venant's
  // torsion (tau_max = T / (alpha a b^2), alpha = 0.246 at a / b = 2 (Timoshenko and Goodier,
  // table 9; the series gives 0.24588), the short side's middle k = 0.795 tau_max); exact for an
  // end-loaded beam up to the single precision of the stored modes (1e-6).
  const Superelement se =
      test::Reduce(test::StraightBeamYaml(1.0, 10, "{shape: rectangle, width: 0.02, height: 0.04}",
                                          "{E: 2.1e11, nu: 0.3, rho: 7850}", "[{name: A}, {name: B}]"));
  ASSERT_TRUE(se.stress.has_value());
  const ModalStress& s = *se.stress;
  EXPECT_EQ(s.method, "beam_fibres");
  Eigen::Matrix<double, 6, 1> load;
  load << 1000, 100, -100, 10, 0, 0;
  const Eigen::VectorXd q = ClampedSolution(se, load);
  // Element 4 ends at x = 0.5: its second end.
  const Eigen::Matrix<double, 6, 1> sf = s.section_forces.middleRows(12 * 4 + 6, 6).cast<double>() * q;
  const double N = 1000, Vy = 100, Vz = -100, T = 10, My = -Vz * 0.5, Mz = Vy * 0.5;
  Eigen::Matrix<double, 6, 1> expected;
  expected << N, Vy, Vz, T, My, Mz;
  EXPECT_LT((sf - expected).cwiseAbs().maxCoeff(), 1e-6 * N) << sf.transpose();
  const double A = 0.02 * 0.04, Iy = 0.02 * std::pow(0.04, 3) / 12, Iz = 0.04 * std::pow(0.02, 3) / 12;
  const double tau_max = T / (0.24588 * 0.04 * 0.02 * 0.02);
  struct Expect {
    double y, z, sigma, tau_xy, tau_xz;
  };
  const Expect fibres[] = {
      {0.01, 0.02, N / A + My * 0.02 / Iy - Mz * 0.01 / Iz, 0, 0},            // corner
      {-0.01, -0.02, N / A - My * 0.02 / Iy + Mz * 0.01 / Iz, 0, 0},          // opposite corner
      {0.01, 0, N / A - Mz * 0.01 / Iz, 0, tau_max + 1.5 * Vz / A},           // long side's middle
      {0, 0.02, N / A + My * 0.02 / Iy, 1.5 * Vy / A - 0.7950 * tau_max, 0},  // short side's middle
  };
  for (const Expect& e : fibres) {
    const int p = NearestPoint(s, Eigen::Vector3d(0.5, e.y, e.z));
    ASSERT_LT((s.points.row(p) - Eigen::RowVector3d(0.5, e.y, e.z)).norm(), 1e-12);
    const Eigen::Matrix<double, 6, 1> sigma = StressAt(s, p, q);
    const double scale = std::abs(e.sigma) + tau_max;
    EXPECT_NEAR(sigma[0], e.sigma, 1e-6 * scale) << e.y << " " << e.z;
    EXPECT_NEAR(sigma[5], e.tau_xy, 2e-4 * scale) << e.y << " " << e.z;
    EXPECT_NEAR(sigma[4], e.tau_xz, 2e-4 * scale) << e.y << " " << e.z;
    EXPECT_NEAR(sigma[1], 0.0, 1e-6 * scale);
    EXPECT_NEAR(sigma[2], 0.0, 1e-6 * scale);
    EXPECT_NEAR(sigma[3], 0.0, 1e-6 * scale);
  }
  EXPECT_NEAR(VonMises(StressAt(s, NearestPoint(s, Eigen::Vector3d(0.5, 0.01, 0.02)), q)),
              std::abs(N / A + My * 0.02 / Iy - Mz * 0.01 / Iz), 1e-6 * (N / A + My * 0.02 / Iy + Mz * 0.01 / Iz));
}

TEST(ModalStress, AffineFieldsHaveExactGradientsAndGreenLagrangeStress) {
  // Reference: an affine displacement u = A X has the constant gradient A, which every element
  // represents: the projected nodal gradients are A to single precision at every node, and the
  // recovered stress at amplitude q is St. Venant-Kirchhoff's S = D E with the exact Green-Lagrange
  // strain E = (q A + q A^T + q^2 A^T A) / 2 (linear plus quadratic part; no other term exists).
  const PartSpec part = ParsePart(SolidBar("hexahedra", 0.025), "bar.yaml", {});
  const FeModel model = BuildSolidModel(part);
  Eigen::Matrix3d A;
  A << 0.3, -0.2, 0.1, 0.5, 0.05, -0.4, 0.2, 0.1, -0.15;
  Eigen::MatrixXd field(model.nodes.rows() * 3, 1);
  for (long i = 0; i < model.nodes.rows(); ++i) field.block<3, 1>(3 * i, 0) = A * model.nodes.row(i).transpose();
  const ModalStress s = SolidModalStress(SolidType::kHex20, model.nodes, model.cells, part.material, field, true);
  ASSERT_EQ(s.gradients.rows(), 9 * model.nodes.rows());
  double worst = 0;
  for (long i = 0; i < model.nodes.rows(); ++i) {
    const Eigen::Matrix<double, 9, 1> h = s.gradients.block<9, 1>(9 * i, 0).cast<double>();
    worst = std::max(
        worst, (Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(h.data()) - A).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(worst, 1e-6);
  const double q = 0.7, E = part.material.E, nu = part.material.nu;
  const Eigen::Matrix3d G = 0.5 * (q * A + q * A.transpose() + q * q * A.transpose() * A);
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
  const Eigen::Matrix3d S = lambda * G.trace() * Eigen::Matrix3d::Identity() + 2 * mu * G;
  Eigen::Matrix<double, 6, 1> expected;
  expected << S(0, 0), S(1, 1), S(2, 2), S(1, 2), S(0, 2), S(0, 1);
  const Eigen::VectorXd amplitude = Eigen::VectorXd::Constant(1, q);
  for (int p : {0, 17, int(model.nodes.rows()) - 1}) {
    EXPECT_LT((PointStress(s, p, amplitude) - expected).cwiseAbs().maxCoeff(), 1e-6 * expected.cwiseAbs().maxCoeff())
        << p;
  }
  // A part with modal derivatives stores the gradients of its whole basis (and the file keeps
  // them); one without does not.
  const Superelement se = test::Reduce(test::Replace(SolidBar("hexahedra", 0.025), "internal_modes: 4}",
                                                     "internal_modes: 4, modal_derivatives: {of: internal}}"));
  ASSERT_TRUE(se.stress.has_value());
  EXPECT_GT(se.n_modal_derivatives, 0);
  EXPECT_EQ(se.stress->gradients.rows(), 9 * se.stress->n_points());
  EXPECT_EQ(se.stress->gradients.cols(), se.n_reduced_dofs());
  EXPECT_EQ(se.stress->E, part.material.E);
  const std::string path = "/tmp/femb_modal_stress_gradients_" + std::to_string(::getpid()) + ".h5";
  WriteSuperelementFile(se, path);
  const Superelement back = ReadSuperelementFile(path);
  std::remove(path.c_str());
  ASSERT_TRUE(back.stress.has_value());
  EXPECT_EQ(back.stress->gradients, se.stress->gradients);
  EXPECT_EQ(back.stress->nu, se.stress->nu);
  EXPECT_EQ(test::Reduce(SolidBar("hexahedra", 0.025)).stress->gradients.size(), 0);
  // Without gradients the same field gives the linear stress alone.
  const ModalStress linear = SolidModalStress(SolidType::kHex20, model.nodes, model.cells, part.material, field);
  EXPECT_EQ(linear.gradients.size(), 0);
  const Eigen::Matrix3d Gl = 0.5 * q * (A + A.transpose());
  EXPECT_NEAR(PointStress(linear, 5, amplitude)[5], 2 * mu * Gl(0, 1), 1e-6 * E);
}

TEST(ModalStress, VonMisesAndPrincipalStressesOfKnownStates) {
  Eigen::Matrix<double, 6, 1> s;
  s << 100, 0, 0, 0, 0, 0;  // uniaxial
  EXPECT_NEAR(VonMises(s), 100, 1e-12);
  s << 0, 0, 0, 0, 0, 50;  // pure shear xy: sqrt(3) tau, principal +-tau
  EXPECT_NEAR(VonMises(s), std::sqrt(3.0) * 50, 1e-12);
  EXPECT_LT((PrincipalStresses(s) - Eigen::Vector3d(50, 0, -50)).norm(), 1e-12);
  s << 7, 7, 7, 0, 0, 0;  // hydrostatic
  EXPECT_NEAR(VonMises(s), 0, 1e-12);
  s << 30, 20, 10, 4, -3, 5;  // invariants: trace and the second invariant
  const Eigen::Vector3d p = PrincipalStresses(s);
  EXPECT_NEAR(p.sum(), 60, 1e-12);
  EXPECT_GE(p[0], p[1]);
  EXPECT_GE(p[1], p[2]);
  const double I2 = 30 * 20 + 20 * 10 + 10 * 30 - 16 - 9 - 25;
  EXPECT_NEAR(p[0] * p[1] + p[1] * p[2] + p[2] * p[0], I2, 1e-10);
}

// The closed form against Eigen's iterative solver on random tensors and on near-double and
// triple roots (where acos loses half the digits): within 1e-7 of the deviator's size (the
// animation stores the principal stresses in single precision, 6e-8 relative).
TEST(ModalStress, PrincipalStressesMatchTheIterativeSolver) {
  std::srand(7);
  double worst = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    Eigen::Matrix<double, 6, 1> s = Eigen::Matrix<double, 6, 1>::Random() * 1e8;
    if (trial % 3 == 1) {  // a double root: R diag(a, a, b) R^T, perturbed by 1e-9
      const Eigen::Matrix3d Q = Eigen::Quaterniond(Eigen::Vector4d::Random().normalized()).toRotationMatrix();
      const Eigen::Vector3d l(3e7, 3e7 * (1 + 1e-9 * (trial % 7)), -5e7);
      const Eigen::Matrix3d S = Q * l.asDiagonal() * Q.transpose();
      s << S(0, 0), S(1, 1), S(2, 2), S(1, 2), S(0, 2), S(0, 1);
    }
    if (trial % 3 == 2) s.head<3>().setConstant(4e7), s.tail<3>() *= 1e-6;  // nearly hydrostatic
    Eigen::Matrix3d S;
    S << s[0], s[5], s[4], s[5], s[1], s[3], s[4], s[3], s[2];
    const Eigen::Vector3d l = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(S, Eigen::EigenvaluesOnly).eigenvalues();
    const double scale = (S - S.trace() / 3 * Eigen::Matrix3d::Identity()).norm() + 1e-300;
    worst = std::max(worst, (PrincipalStresses(s) - Eigen::Vector3d(l[2], l[1], l[0])).norm() / scale);
  }
  EXPECT_LT(worst, 1e-7);
  std::printf("principal stresses: largest difference %.2e of the deviator's size\n", worst);
}

// The largest and smallest principal stress by Newton's method on the cubic (the animation's
// fields) against Eigen's iterative solver on the same kinds of tensors: within 3e-7 of the
// deviator's size (the fields are stored in single precision), near double and triple roots too.
TEST(ModalStress, ExtremePrincipalStressesMatchTheIterativeSolver) {
  std::srand(11);
  double worst = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    Eigen::Matrix<double, 6, 1> s = Eigen::Matrix<double, 6, 1>::Random() * 1e8;
    if (trial % 3 == 1) {
      const Eigen::Matrix3d Q = Eigen::Quaterniond(Eigen::Vector4d::Random().normalized()).toRotationMatrix();
      const double a = trial % 2 ? 3e7 : -5e7, b = trial % 2 ? -5e7 : 3e7;  // double root largest or smallest
      const Eigen::Vector3d l(a, a * (1 + 1e-9 * (trial % 7)), b);
      const Eigen::Matrix3d S = Q * l.asDiagonal() * Q.transpose();
      s << S(0, 0), S(1, 1), S(2, 2), S(1, 2), S(0, 2), S(0, 1);
    }
    if (trial % 3 == 2) s.head<3>().setConstant(4e7), s.tail<3>() *= 1e-6;
    Eigen::Matrix3d S;
    S << s[0], s[5], s[4], s[5], s[1], s[3], s[4], s[3], s[2];
    const Eigen::Vector3d l = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(S, Eigen::EigenvaluesOnly).eigenvalues();
    const double scale = (S - S.trace() / 3 * Eigen::Matrix3d::Identity()).norm() + 1e-300;
    worst = std::max(worst, (ExtremePrincipalStresses(s) - Eigen::Vector2d(l[2], l[0])).norm() / scale);
  }
  EXPECT_LT(worst, 3e-7);
  std::printf("largest and smallest principal stress: largest difference %.2e of the deviator's size\n", worst);
}

TEST(ModalStress, FileKeepsThemAndOffSwitchDropsThem) {
  const std::string yaml = test::StraightBeamYaml(1.0, 4, "{shape: circle, diameter: 0.02}",
                                                  "{E: 2.1e11, nu: 0.3, rho: 7850}", "[{name: A}, {name: B}]");
  const Superelement se = test::Reduce(yaml);
  ASSERT_TRUE(se.stress.has_value());
  EXPECT_EQ(se.stress->n_points(), 4 * 2 * 8);  // 8 fibres at both ends of 4 elements
  const std::string path = "/tmp/femb_modal_stress_test_" + std::to_string(::getpid()) + ".h5";
  WriteSuperelementFile(se, path);
  const Superelement back = ReadSuperelementFile(path);
  std::remove(path.c_str());
  ASSERT_TRUE(back.stress.has_value());
  EXPECT_EQ(back.stress->method, se.stress->method);
  EXPECT_EQ(back.stress->node, se.stress->node);
  EXPECT_EQ(back.stress->points, se.stress->points);
  EXPECT_EQ(back.stress->modes, se.stress->modes);
  EXPECT_EQ(back.stress->section_forces, se.stress->section_forces);
  EXPECT_EQ(back.stress->element_axes, se.stress->element_axes);
  EXPECT_FALSE(test::Reduce(yaml, {"reduction.stresses=false"}).stress.has_value());
  EXPECT_FALSE(test::Reduce(yaml, {"reduction.keep_mesh=false"}).stress.has_value());
  const std::string why = test::ThrownMessage([&] {
    ParsePart(yaml, "p.yaml", {"reduction.keep_mesh=false", "reduction.stresses=true"});
  });
  EXPECT_NE(why.find("needs the mesh"), std::string::npos) << why;
}

}  // namespace
}  // namespace femb
