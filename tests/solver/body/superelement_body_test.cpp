// Superelement body in absolute interface coordinates: the elastic force is the gradient of the
// strain energy, and the tangent K1+K2+K3(+K4) is its derivative — both checked by central
// finite differences — and both are invariant under rigid motions.
#include "solver/body/superelement_body.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "solver/rotation.h"
#include "test_util.h"

namespace femb {
namespace {

Superelement Rod(const std::string& frame, int modes = 3) {
  return test::Reduce(test::StraightBeamYaml(
                          0.5, 8, "{shape: rectangle, width: 0.02, height: 0.01}", "{E: 7.0e10, nu: 0.3, rho: 2700}",
                          "[{name: A}, {name: B}]",
                          "reduction: {internal_modes: " + std::to_string(modes) + ", geometric_stiffening: false}\n"),
                      {"reduction.floating_frame=" + frame});
}

// A three-interface part (T-shape) to exercise N > 2.
Superelement Tee() {
  return test::Reduce(
      "name: tee\ntype: beam\nmaterial: {E: 7.0e10, nu: 0.3, rho: 2700}\n"
      "section: {shape: circle, diameter: 0.01}\n"
      "beam:\n  points: {A: [0, 0, 0], C: [0.2, 0, 0], B: [0.4, 0, 0], D: [0.2, 0.3, 0]}\n"
      "  segments: [{from: A, to: C, elements: 3}, {from: C, to: B, elements: 3}, {from: C, to: D, elements: 3}]\n"
      "interfaces: [{name: A}, {name: B}, {name: D}]\n"
      "reduction: {internal_modes: 2, floating_frame: mean_axes, geometric_stiffening: false}\n");
}

// n entries uniform in [-1, 1], drawn in order from `rng`.
Eigen::VectorXd Uniform(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v[i] = u(rng);
  return v;
}

// A deformed configuration: large rigid rotation and translation, plus node perturbations of
// the given size (displacements relative to the body size, rotations in rad).
BodyConfiguration Deformed(const SuperelementBody& body, double size, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  BodyConfiguration c = InitialConfiguration(body);
  const Eigen::Matrix3d Rr = ExpSO3(Eigen::Vector3d(0.7, -1.1, 0.4));
  const Eigen::Vector3d tr(0.3, -0.2, 1.5);
  for (int k = 0; k < body.n_nodes(); ++k) {
    c.x[k] = Rr * c.x[k] + tr + 0.05 * size * Eigen::Vector3d(u(rng), u(rng), u(rng));
    c.R[k] = ExpSO3(size * Eigen::Vector3d(u(rng), u(rng), u(rng))) * Rr * c.R[k];
  }
  for (int m = 0; m < c.eta.size(); ++m) c.eta[m] = 1e-3 * size * u(rng);
  return c;
}

// Applies eps * e (per node dx, dpi spatial; then d eta).
BodyConfiguration Perturb(const BodyConfiguration& c, const Eigen::VectorXd& e, double eps) {
  BodyConfiguration p = c;
  for (size_t k = 0; k < c.x.size(); ++k) {
    p.x[k] += eps * e.segment<3>(6 * k);
    p.R[k] = ExpSO3(eps * Eigen::Vector3d(e.segment<3>(6 * k + 3))) * c.R[k];
  }
  p.eta += eps * e.tail(c.eta.size());
  return p;
}

struct Evaluation {
  Eigen::VectorXd f;
  double energy;
};

Evaluation ElasticAt(const SuperelementBody& body, const BodyConfiguration& c, FrameSolution guess) {
  const FrameSolution frame = SolveFrame(body, c, guess);
  EXPECT_TRUE(frame.ok);
  Evaluation e;
  ElasticForce(body, test::Lvalue(Evaluate(body, c, frame)), &e.f, nullptr);
  e.energy = ElasticEnergy(body, test::Lvalue(Evaluate(body, c, frame)));
  return e;
}

void CheckAgainstFiniteDifferences(const Superelement& se, const SuperelementOptions& options, double size) {
  const SuperelementBody body(se, options);
  const BodyConfiguration c = Deformed(body, size, 42);
  const FrameSolution frame = SolveFrame(body, c, GuessFrame(body, c));
  ASSERT_TRUE(frame.ok);
  Eigen::VectorXd f;
  Eigen::MatrixXd K;
  ElasticForce(body, test::Lvalue(Evaluate(body, c, frame)), &f, &K);
  const int n = body.n_coordinates();
  Eigen::MatrixXd K_fd(n, n);
  Eigen::VectorXd f_fd(n);
  for (int i = 0; i < n; ++i) {
    const Eigen::VectorXd e = Eigen::VectorXd::Unit(n, i);
    // Node coordinates: 1e-6 (m, rad). Modal coordinates are mass-normalized: one unit moves the
    // body by ~1/sqrt(mass), so their step is 1e-6 of the body size in displacement (a 2 g leaf:
    // 2e-9); a coordinate that turns the floating frame strongly (a thin leaf's torsion mode) gets
    // a proportionally smaller one.
    double extent = 0.0;
    for (const InterfaceNode& node : se.interfaces)
      extent = std::max(extent, (node.position - se.mass_properties.center_of_mass).norm());
    const double h = (i < se.n_interface_dofs() ? 1e-6 : 1e-6 * extent * std::sqrt(se.mass_properties.mass)) /
                     std::max(1.0, se.floating_frame.Phi_CB.col(i).norm());
    const Evaluation plus = ElasticAt(body, Perturb(c, e, h), frame);
    const Evaluation minus = ElasticAt(body, Perturb(c, e, -h), frame);
    K_fd.col(i) = (plus.f - minus.f) / (2 * h);
    f_fd[i] = (plus.energy - minus.energy) / (2 * h);
  }
  // Central differences: truncation O(h^2), round-off O(eps |f| / h): 1e-6 relative is ample.
  EXPECT_LT((K - K_fd).norm(), 1e-6 * K.norm())
      << "tangent, approximated=" << options.approximated << "\nK - K_fd (max) " << (K - K_fd).cwiseAbs().maxCoeff();
  if (!options.approximated) {
    // The force is the gradient of the strain energy.
    EXPECT_LT((f - f_fd).norm(), 1e-6 * f.norm()) << "force vs energy gradient";
  }
  EXPECT_GT(f.norm(), 0.0);
}

TEST(SuperelementBody, ExactTangentMatchesFiniteDifferences) {
  for (const std::string frame : {"center_of_mass", "mean_axes", "interface:A", "cardona"}) {
    SCOPED_TRACE(frame);
    CheckAgainstFiniteDifferences(Rod(frame), {false, true}, 0.3);
  }
  CheckAgainstFiniteDifferences(Tee(), {false, true}, 0.3);
}

TEST(SuperelementBody, ApproximatedTransformationTangentMatchesFiniteDifferences) {
  CheckAgainstFiniteDifferences(Rod("center_of_mass"), {true, true}, 0.3);
  CheckAgainstFiniteDifferences(Tee(), {true, true}, 0.3);
}

TEST(SuperelementBody, PolynomialInternalForceTangentMatchesFiniteDifferences) {
  // A solid leaf spring with modal derivatives: the local force is the Green-Lagrange polynomial;
  // force = energy gradient and the full tangent (its Hessian in K1, K2-K4 from the force) are
  // checked like the linear body's, and the polynomial changes the force.
  const Superelement se = test::Reduce(
      "name: leaf\ntype: solid\nmaterial: {E: 2.1e11, nu: 0.3, rho: 7850}\n"
      "geometry: {shape: box, size: [0.05, 0.01, 0.0005]}\n"
      "mesh: {size: 0.0025, order: 2, elements: hexahedra}\n"
      "interfaces: [{name: A, group: xmin}, {name: B, group: xmax}]\n"
      "reduction: {internal_modes: 2, modal_derivatives: {pairs: [[8, 8], [7, 7], [8, 12]]}}\n");
  ASSERT_TRUE(se.polynomial.has_value());
  ASSERT_EQ(se.n_modal_derivatives, 3);
  {
    SuperelementOptions lin;
    lin.polynomial_force = false;
    SCOPED_TRACE("linear");
    CheckAgainstFiniteDifferences(se, lin, 0.05);
  }
  CheckAgainstFiniteDifferences(se, {false, true}, 0.05);
  CheckAgainstFiniteDifferences(se, {true, true}, 0.05);
  SuperelementOptions linear;
  linear.polynomial_force = false;
  const SuperelementBody with(se, {}), without(se, linear);
  const BodyConfiguration c = Deformed(with, 0.05, 3);
  const FrameSolution frame = SolveFrame(with, c, GuessFrame(with, c));
  Eigen::VectorXd f1, f2;
  ElasticForce(with, test::Lvalue(Evaluate(with, c, frame)), &f1, nullptr);
  ElasticForce(without, test::Lvalue(Evaluate(without, c, frame)), &f2, nullptr);
  EXPECT_GT((f1 - f2).norm(), 1e-3 * f2.norm());
}

TEST(SuperelementBody, TangentIsSymmetricAtEquilibriumFreeConfiguration) {
  // The exact force is a gradient, so its derivative (a Hessian) is symmetric everywhere.
  const SuperelementBody body(Rod("center_of_mass"), {false, true});
  const BodyConfiguration c = Deformed(body, 0.2, 7);
  const FrameSolution frame = SolveFrame(body, c, GuessFrame(body, c));
  Eigen::VectorXd f;
  Eigen::MatrixXd K;
  ElasticForce(body, test::Lvalue(Evaluate(body, c, frame)), &f, &K);
  // A Hessian on SO(3) with spatial variations is symmetric up to the term (f_moment x) — the
  // asymmetric part is bounded by the moments: check it is small relative to K.
  EXPECT_LT((K - K.transpose()).norm(), 1e-3 * K.norm());
}

TEST(SuperelementBody, RigidMotionsAreForceFreeAndForcesRotateWithTheBody) {
  const Superelement se = Rod("center_of_mass");
  const SuperelementBody body(se, {false, true});
  BodyConfiguration c0 = InitialConfiguration(body);
  Eigen::VectorXd f;
  ElasticForce(body, test::Lvalue(Evaluate(body, c0, SolveFrame(body, c0, body.InitialFrame()))), &f, nullptr);
  EXPECT_LT(f.norm(), 1e-12);
  // Rigid motion of the undeformed body: still no force; frame follows.
  const Eigen::Matrix3d Rr = ExpSO3(Eigen::Vector3d(2.0, -0.5, 1.0));
  const Eigen::Vector3d t(1, 2, 3);
  BodyConfiguration moved = c0;
  for (int k = 0; k < body.n_nodes(); ++k) {
    moved.x[k] = Rr * c0.x[k] + t;
    moved.R[k] = Rr * c0.R[k];
  }
  const FrameSolution frame = SolveFrame(body, moved, GuessFrame(body, moved));
  ASSERT_TRUE(frame.ok);
  ElasticForce(body, test::Lvalue(Evaluate(body, moved, frame)), &f, nullptr);
  EXPECT_LT(f.norm(), 1e-14 * se.K.cwiseAbs().maxCoeff());  // round-off of positions ~3 m
  EXPECT_LT((frame.R - Rr).norm(), 1e-12);
  EXPECT_LT((frame.x - (Rr * body.InitialFrame().x + t)).norm(), 1e-12);
  // A deformed configuration moved rigidly: same energy, forces rotated.
  const BodyConfiguration d = Deformed(body, 0.2, 3);
  BodyConfiguration dm = d;
  for (int k = 0; k < body.n_nodes(); ++k) {
    dm.x[k] = Rr * d.x[k] + t;
    dm.R[k] = Rr * d.R[k];
  }
  Eigen::VectorXd fd, fdm;
  const FrameSolution a = SolveFrame(body, d, GuessFrame(body, d)), b = SolveFrame(body, dm, GuessFrame(body, dm));
  ElasticForce(body, test::Lvalue(Evaluate(body, d, a)), &fd, nullptr);
  ElasticForce(body, test::Lvalue(Evaluate(body, dm, b)), &fdm, nullptr);
  EXPECT_NEAR(ElasticEnergy(body, test::Lvalue(Evaluate(body, d, a))),
              ElasticEnergy(body, test::Lvalue(Evaluate(body, dm, b))),
              1e-10 * ElasticEnergy(body, test::Lvalue(Evaluate(body, d, a))));
  for (int k = 0; k < 2 * body.n_nodes(); ++k) {
    EXPECT_LT((Rr * fd.segment<3>(3 * k) - fdm.segment<3>(3 * k)).norm(), 1e-9 * fd.norm());
  }
  // Total force and moment about the origin of the elastic forces vanish (internal forces).
  Eigen::Vector3d F = Eigen::Vector3d::Zero(), Mo = Eigen::Vector3d::Zero();
  for (int k = 0; k < body.n_nodes(); ++k) {
    F += fd.segment<3>(6 * k);
    Mo += fd.segment<3>(6 * k + 3) + d.x[k].cross(fd.segment<3>(6 * k));
  }
  EXPECT_LT(F.norm(), 1e-9 * fd.norm());
  EXPECT_LT(Mo.norm(), 1e-9 * fd.norm());
}

TEST(SuperelementBody, SmallDeformationsReproduceTheReducedStiffness) {
  // About the undeformed placement the tangent is Rbar K Rbar^T for deformation directions
  // (K1 = T^T K T with T removing rigid motions, thesis 3.25, and K2 = K3 = 0 with no load).
  const Superelement se = Rod("center_of_mass");
  const Eigen::Matrix3d Rp = ExpSO3(Eigen::Vector3d(0.3, 0.2, -0.4));
  const SuperelementBody body(se, {false, true}, Rp, Eigen::Vector3d(1, 0, 0));
  const BodyConfiguration c = InitialConfiguration(body);
  Eigen::MatrixXd Kt;
  Eigen::VectorXd f;
  ElasticForce(body, test::Lvalue(Evaluate(body, c, SolveFrame(body, c, body.InitialFrame()))), &f, &Kt);
  const int n = body.n_coordinates();
  Eigen::MatrixXd Rbar = Eigen::MatrixXd::Identity(n, n);
  for (int a = 0; a < 2 * body.n_nodes(); ++a) Rbar.block<3, 3>(3 * a, 3 * a) = Rp;
  EXPECT_LT((Kt - Rbar * se.K * Rbar.transpose()).norm(), 1e-9 * se.K.norm());
}

TEST(SuperelementBody, GyroscopicMatrixMatchesFiniteDifferencesAndMassIsPtMP) {
  for (bool option_b : {false, true}) {
    SuperelementOptions options;
    options.cardona_option_b = option_b;
    const SuperelementBody body(Tee(), options);
    const BodyConfiguration c = Deformed(body, 0.2, 11);
    const FrameSolution frame = SolveFrame(body, c, GuessFrame(body, c));
    ASSERT_TRUE(frame.ok);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const int n = body.n_coordinates();
    Eigen::VectorXd w(n), wdot(n);
    for (int i = 0; i < n; ++i) {
      w[i] = 3.0 * u(rng);
      wdot[i] = 10.0 * u(rng);
    }
    Eigen::VectorXd f;
    Eigen::MatrixXd Mg, C;
    InertiaForce(body, test::Lvalue(Evaluate(body, c, frame)), w, wdot, &f, &Mg, &C);
    Eigen::MatrixXd C_fd(n, n), M_fd(n, n);
    for (int i = 0; i < n; ++i) {
      const double h = 1e-6;
      Eigen::VectorXd fp, fm;
      InertiaForce(body, test::Lvalue(Evaluate(body, c, frame)), w + h * Eigen::VectorXd::Unit(n, i), wdot, &fp,
                   nullptr, nullptr);
      InertiaForce(body, test::Lvalue(Evaluate(body, c, frame)), w - h * Eigen::VectorXd::Unit(n, i), wdot, &fm,
                   nullptr, nullptr);
      C_fd.col(i) = (fp - fm) / (2 * h);
      InertiaForce(body, test::Lvalue(Evaluate(body, c, frame)), w, wdot + h * Eigen::VectorXd::Unit(n, i), &fp,
                   nullptr, nullptr);
      InertiaForce(body, test::Lvalue(Evaluate(body, c, frame)), w, wdot - h * Eigen::VectorXd::Unit(n, i), &fm,
                   nullptr, nullptr);
      M_fd.col(i) = (fp - fm) / (2 * h);
    }
    EXPECT_LT((C - C_fd).norm(), 1e-6 * C.norm()) << "option B " << option_b;
    EXPECT_LT((Mg - M_fd).norm(), 1e-6 * Mg.norm());
    EXPECT_GT(C.norm(), 0.0);
    // The kinetic energy is w^T M_g w / 2.
    EXPECT_NEAR(KineticEnergy(body, test::Lvalue(Evaluate(body, c, frame)), w), 0.5 * w.dot(Mg * w),
                1e-12 * w.dot(Mg * w));
  }
}

TEST(SuperelementBody, MomentumDerivativesMatchFiniteDifferences) {
  // d(M_g w)/dq at fixed spatial velocities w, options A and B, against central differences of
  // the momentum M_g w (the frame re-solved at each perturbed configuration); the derivatives
  // of MomentumSource in w and p likewise, and the inertia force's configuration derivative.
  for (bool option_b : {false, true}) {
    SuperelementOptions options;
    options.cardona_option_b = option_b;
    options.exact_inertia = false;  // the corotational inertia's momentum (thesis 3.22) is what is checked
    const SuperelementBody body(Tee(), options);
    const BodyConfiguration c = Deformed(body, 0.1, 5);
    const FrameSolution frame = SolveFrame(body, c, GuessFrame(body, c));
    const int n = body.n_coordinates();
    std::mt19937 rng(3);
    const Eigen::VectorXd w = Uniform(n, rng);
    const Eigen::MatrixXd D = test::MomentumDerivativeOf(body, test::MapsAt(body, c, frame), w);
    Eigen::MatrixXd fd(n, n);
    const double eps = 1e-6;
    for (int i = 0; i < n; ++i) {
      const Eigen::VectorXd e = Eigen::VectorXd::Unit(n, i);
      const BodyConfiguration cp = Perturb(c, e, eps), cm = Perturb(c, e, -eps);
      fd.col(i) = (test::MapsAt(body, cp, SolveFrame(body, cp, frame)).Mg * w -
                   test::MapsAt(body, cm, SolveFrame(body, cm, frame)).Mg * w) /
                  (2 * eps);
    }
    EXPECT_LT((D - fd).norm(), 1e-6 * fd.norm()) << (option_b ? "option B" : "option A");

    // MomentumSource derivatives in w and p (bilinear: central differences are exact up to
    // round-off).
    const Eigen::VectorXd p = Uniform(n, rng);
    Eigen::MatrixXd d_w, d_p, fd_w(n, n), fd_p(n, n);
    const BodyVelocityMaps maps = test::MapsAt(body, c, frame);
    BodyScratch scratch;
    MomentumSourceDerivatives(body, test::MapsAt(body, c, frame), w, p, d_w, d_p, scratch);
    for (int i = 0; i < n; ++i) {
      const Eigen::VectorXd e = Eigen::VectorXd::Unit(n, i);
      fd_w.col(i) = (test::MomentumSourceOf(body, maps, w + e, p) - test::MomentumSourceOf(body, maps, w - e, p)) / 2.0;
      fd_p.col(i) = (test::MomentumSourceOf(body, maps, w, p + e) - test::MomentumSourceOf(body, maps, w, p - e)) / 2.0;
    }
    EXPECT_LT((d_w - fd_w).norm(), 1e-12 * fd_w.norm()) << (option_b ? "option B" : "option A");
    EXPECT_LT((d_p - fd_p).norm(), 1e-12 * fd_p.norm()) << (option_b ? "option B" : "option A");

    // Configuration derivative of the inertia force: d(M_g wdot)/dq (analytic) against central
    // differences of f_in at w = 0 (where f_in = M_g wdot exactly), and the full derivative
    // (quadratic terms by differences inside the body) against differences of f_in.
    const Eigen::VectorXd wdot = Uniform(n, rng);
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
    for (bool full : {false, true}) {
      const Eigen::MatrixXd K_in =
          test::InertiaConfigurationTangentOf(body, Evaluate(body, c, frame), full ? w : zero, wdot, full);
      Eigen::MatrixXd fd_in(n, n);
      for (int i = 0; i < n; ++i) {
        const Eigen::VectorXd e = Eigen::VectorXd::Unit(n, i);
        const BodyConfiguration cp = Perturb(c, e, eps), cm = Perturb(c, e, -eps);
        Eigen::VectorXd fp, fm;
        InertiaForce(body, test::Lvalue(Evaluate(body, cp, SolveFrame(body, cp, frame))), full ? w : zero, wdot, &fp,
                     nullptr, nullptr);
        InertiaForce(body, test::Lvalue(Evaluate(body, cm, SolveFrame(body, cm, frame))), full ? w : zero, wdot, &fm,
                     nullptr, nullptr);
        fd_in.col(i) = (fp - fm) / (2 * eps);
      }
      EXPECT_LT((K_in - fd_in).norm(), 1e-5 * fd_in.norm())
          << (option_b ? "option B" : "option A") << (full ? ", full" : ", M_g wdot");
    }
  }
}

// The exact inertia's momentum p = MassTimes(d, w) (the midpoint scheme's): its configuration
// derivative at fixed w (MomentumConfigurationTangent: the frame's turning analytic, the local
// coordinates' share by differences in q_loc) against central differences of p with the frame
// re-solved at each perturbed configuration.
TEST(SuperelementBody, ExactMomentumConfigurationTangentMatchesFiniteDifferences) {
  const SuperelementBody body(Tee(), SuperelementOptions{});
  ASSERT_TRUE(body.has_exact_inertia());
  const BodyConfiguration c = Deformed(body, 0.1, 5);
  const FrameSolution frame = SolveFrame(body, c, GuessFrame(body, c));
  const int n = body.n_coordinates();
  std::mt19937 rng(3);
  const Eigen::VectorXd w = Uniform(n, rng);
  BodyData d = Evaluate(body, c, frame);
  BodyData side;
  Eigen::MatrixXd D;
  MomentumConfigurationTangent(body, d, w, side, D);
  Eigen::MatrixXd fd(n, n);
  const double eps = 1e-6;
  for (int i = 0; i < n; ++i) {
    const Eigen::VectorXd e = Eigen::VectorXd::Unit(n, i);
    const BodyConfiguration cp = Perturb(c, e, eps), cm = Perturb(c, e, -eps);
    BodyData dp = Evaluate(body, cp, SolveFrame(body, cp, frame));
    BodyData dm = Evaluate(body, cm, SolveFrame(body, cm, frame));
    fd.col(i) = (MassTimes(body, dp, w) - MassTimes(body, dm, w)) / (2 * eps);
  }
  std::printf("[ info ] exact momentum's configuration tangent against differences: %.2e\n",
              (D - fd).norm() / fd.norm());
  EXPECT_LT((D - fd).norm(), 1e-6 * fd.norm());
}

TEST(SuperelementBody, InertiaForceIsTheLagrangianDerivativeAlongAMotion) {
  // Along a smooth motion q(t), d/dt (dT/dw) - (dT/dq) = f_in and the power balance
  // dT/dt = w . f_in holds for the inertia force, corotational (thesis 3.22) and exact. Check the
  // power balance with central differences in time on a rigid-deformable motion of the Tee; the
  // momentum form of the midpoint integrator with the corotational inertia.
  for (const bool exact : {false, true}) {
    SuperelementOptions options;
    options.exact_inertia = exact;
    const SuperelementBody body(Tee(), options);
    ASSERT_EQ(body.has_exact_inertia(), exact);
    const BodyConfiguration c0 = Deformed(body, 0.1, 21);
    const int n = body.n_coordinates();
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Eigen::VectorXd w0(n), acc(n);
    for (int i = 0; i < n; ++i) {
      w0[i] = u(rng);
      acc[i] = u(rng);
    }
    // q(t) = q0 o exp(t w0 + t^2/2 acc) (node-wise), w(t) = w0 + t acc to first order; use the
    // exact velocity of this curve through the discrete derivative of positions and rotations.
    auto config = [&](double t) { return Perturb(c0, t * w0 + 0.5 * t * t * acc, 1.0); };
    auto velocity = [&](double t) {
      const double h = 1e-6;
      const BodyConfiguration a = config(t - h), b = config(t + h);
      Eigen::VectorXd w(n);
      for (int k = 0; k < body.n_nodes(); ++k) {
        w.segment<3>(6 * k) = (b.x[k] - a.x[k]) / (2 * h);
        w.segment<3>(6 * k + 3) = LogSO3(b.R[k] * a.R[k].transpose()) / (2 * h);
      }
      w.tail(body.n_modes()) = (b.eta - a.eta) / (2 * h);
      return w;
    };
    auto energy = [&](double t) {
      const BodyConfiguration c = config(t);
      return KineticEnergy(body, test::Lvalue(Evaluate(body, c, SolveFrame(body, c, GuessFrame(body, c)))),
                           velocity(t));
    };
    const double t = 0.01, dt = 1e-4;
    const double power_fd = (energy(t + dt) - energy(t - dt)) / (2 * dt);
    const BodyConfiguration c = config(t);
    const Eigen::VectorXd w = velocity(t);
    const Eigen::VectorXd wdot = (velocity(t + dt) - velocity(t - dt)) / (2 * dt);
    Eigen::VectorXd f_in;
    InertiaForce(body, test::Lvalue(Evaluate(body, c, SolveFrame(body, c, GuessFrame(body, c)))), w, wdot, &f_in,
                 nullptr, nullptr);
    EXPECT_NEAR(w.dot(f_in), power_fd, 1e-5 * std::abs(power_fd)) << (exact ? "exact" : "corotational");
    if (exact) {
      // The exact inertia's momentum form (the midpoint scheme with the exact inertia):
      // p = MassTimes (dT/dw), s = MomentumSource at the body's data, with its local term.
      auto momentum_exact = [&](double time) {
        const BodyConfiguration ct = config(time);
        BodyData data = Evaluate(body, ct, SolveFrame(body, ct, GuessFrame(body, ct)));
        return Eigen::VectorXd(MassTimes(body, data, velocity(time)));
      };
      const Eigen::VectorXd pdot_exact = (momentum_exact(t + dt) - momentum_exact(t - dt)) / (2 * dt);
      BodyData d = Evaluate(body, c, SolveFrame(body, c, GuessFrame(body, c)));
      const Eigen::VectorXd p = MassTimes(body, d, w);
      Eigen::VectorXd source;
      MomentumSource(body, d, w, p, source);
      const Eigen::VectorXd balance = pdot_exact - source;
      std::printf("[ info ] exact inertia: momentum form against f_in %.2e (relative)\n",
                  (balance - f_in).norm() / f_in.norm());
      EXPECT_LT((balance - f_in).norm(), 1e-5 * f_in.norm())
          << "exact: f_in " << f_in.transpose() << "\nbalance " << balance.transpose();
      continue;
    }

    // Momentum form used by the midpoint integrator: f_in = dp/dt - s(q, w, p), p = M_g w,
    // s = MomentumSource; dp/dt by central differences along the same motion.
    auto momentum = [&](double time) -> Eigen::VectorXd {
      const BodyConfiguration ct = config(time);
      return test::MapsAt(body, ct, SolveFrame(body, ct, GuessFrame(body, ct))).Mg * velocity(time);
    };
    const Eigen::VectorXd pdot = (momentum(t + dt) - momentum(t - dt)) / (2 * dt);
    const FrameSolution frame = SolveFrame(body, c, GuessFrame(body, c));
    const BodyVelocityMaps maps = test::MapsAt(body, c, frame);
    const Eigen::VectorXd balance = pdot - test::MomentumSourceOf(body, maps, w, maps.Mg * w);
    EXPECT_LT((balance - f_in).norm(), 1e-5 * f_in.norm())
        << "f_in " << f_in.transpose() << "\nbalance " << balance.transpose();
  }
}

}  // namespace
}  // namespace femb
