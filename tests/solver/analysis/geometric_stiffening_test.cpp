// Geometric stiffening inside a body, checked against independent references:
//  - the inertia load factors and the stiffening force's tangent and load derivatives against
//    finite differences, and the factors of a rigid rotation against their closed form;
//  - the stored tensors (basis stress, inertia load case) against closed-form integrals;
//  - a tensioned cantilever in ONE body against the closed form of the tensioned beam.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>

#include "formats/part_file.h"
#include "formats/reduced_polynomial.h"
#include "formats/scene_file.h"
#include "formats/superelement_file.h"
#include "reducer/reduce_part.h"
#include "solver/analysis/dynamic_analysis.h"
#include "solver/analysis/static_analysis.h"
#include "solver/body/superelement_body.h"
#include "solver/rotation.h"
#include "solver/scene/scene_builder.h"
#include "test_util.h"

namespace femb {
namespace {

// The rotating beam example's tube, 1 m: EI = 189.1 N m^2, rho A = 0.1612 kg/m.
constexpr double kL = 1.0, kE = 70e9, kRho = 2700, kRo = 0.01, kRi = 0.009;
const double kI = M_PI / 4 * (std::pow(kRo, 4) - std::pow(kRi, 4));
const double kA = M_PI * (kRo * kRo - kRi * kRi);

Superelement Tube(int internal_modes, bool stiffening, const std::string& frame = "center_of_mass") {
  std::string yaml = test::StraightBeamYaml(kL, 40, "{shape: tube, outer_radius: 0.01, wall: 0.001}",
                                            "{E: 70.0e9, nu: 0.3, rho: 2700}", "[{name: A}, {name: B}]",
                                            "reduction: {internal_modes: " + std::to_string(internal_modes) +
                                                ", geometric_stiffening: " + (stiffening ? "true" : "false") +
                                                ", floating_frame: '" + frame + "'}\n");
  yaml.replace(yaml.find("beam:\n"), 6, "beam:\n  theory: euler_bernoulli\n");  // as the closed forms
  return test::Reduce(yaml);
}

TEST(GeometricStiffening, InertiaLoadFactorsAndTheirDerivativesMatchFiniteDifferences) {
  const Superelement se = Tube(4, true);
  ASSERT_EQ(se.inertia_stiffness.size(), 12u);
  const SuperelementBody body(se, SuperelementOptions{});
  const int n = body.n_coordinates();
  // A body turned and displaced, slightly deformed, moving.
  BodyConfiguration c = InitialConfiguration(body);
  const Eigen::Matrix3d Rg = ExpSO3(Eigen::Vector3d(0.3, -0.2, 0.5));
  for (int k = 0; k < body.n_nodes(); ++k) {
    c.x[k] = Rg * c.x[k] + Eigen::Vector3d(0.1, 0.2, -0.3) + 1e-3 * Eigen::Vector3d(k, -k, 2 * k);
    c.R[k] = ExpSO3(Eigen::Vector3d(0.01 * k, 0.02, -0.01)) * Rg * c.R[k];
  }
  c.eta.setConstant(1e-4);
  const FrameSolution frame = SolveFrame(body, c, GuessFrame(body, c));
  ASSERT_TRUE(frame.ok);
  const Eigen::VectorXd w = Eigen::VectorXd::LinSpaced(n, -3.0, 5.0), wdot = Eigen::VectorXd::LinSpaced(n, 40.0, -20.0);
  const Eigen::Vector3d g(0, 0, -9.81);
  const InertiaLoadFactors load = test::InertiaLoadsOf(body, Evaluate(body, c, frame), w, wdot, g);
  // A rigid rotation about z through the frame origin at Omega: a = (0, 0, 0 | 0 | Omega^2 products).
  {
    const double Omega = 7.0;
    BodyConfiguration c0 = InitialConfiguration(body);
    const FrameSolution f0 = SolveFrame(body, c0, GuessFrame(body, c0));
    Eigen::VectorXd wr = Eigen::VectorXd::Zero(n), wr_dot = Eigen::VectorXd::Zero(n);
    for (int k = 0; k < body.n_nodes(); ++k) {
      const Eigen::Vector3d r = c0.x[k] - f0.x;
      wr.segment<3>(6 * k) = Eigen::Vector3d(0, 0, Omega).cross(r);
      wr.segment<3>(6 * k + 3) = Eigen::Vector3d(0, 0, Omega);
      wr_dot.segment<3>(6 * k) = Eigen::Vector3d(0, 0, Omega).cross(Eigen::Vector3d(wr.segment<3>(6 * k)));
    }
    const InertiaLoadFactors rot =
        test::InertiaLoadsOf(body, Evaluate(body, c0, f0), wr, wr_dot, Eigen::Vector3d::Zero());
    Eigen::Matrix<double, 12, 1> expected = Eigen::Matrix<double, 12, 1>::Zero();
    expected[8] = Omega * Omega;
    EXPECT_LT((rot.a - expected).norm(), 1e-9 * Omega * Omega) << rot.a.transpose();
  }
  Eigen::MatrixXd d_w(12, n), d_wdot(12, n);
  for (int i = 0; i < n; ++i) {
    const double h = 1e-4;  // a is linear in wdot and quadratic in w: central differences are exact up to round-off
    const Eigen::VectorXd e = Eigen::VectorXd::Unit(n, i);
    d_w.col(i) = (test::InertiaLoadsOf(body, Evaluate(body, c, frame), w + h * e, wdot, g).a -
                  test::InertiaLoadsOf(body, Evaluate(body, c, frame), w - h * e, wdot, g).a) /
                 (2 * h);
    d_wdot.col(i) = (test::InertiaLoadsOf(body, Evaluate(body, c, frame), w, wdot + h * e, g).a -
                     test::InertiaLoadsOf(body, Evaluate(body, c, frame), w, wdot - h * e, g).a) /
                    (2 * h);
  }
  EXPECT_LT((load.d_w - d_w).norm(), 1e-9 * d_w.norm());
  EXPECT_LT((load.d_wdot - d_wdot).norm(), 1e-9 * d_wdot.norm());
  // df/da at fixed configuration, and the tangent with the load (central differences over the
  // configuration at fixed a).
  Eigen::VectorXd f;
  Eigen::MatrixXd K, d_load;
  ElasticForce(body, test::Lvalue(Evaluate(body, c, frame)), &f, &K, &load, &d_load);
  Eigen::MatrixXd d_load_fd(n, 12);
  for (int k = 0; k < 12; ++k) {
    InertiaLoadFactors plus = load, minus = load;
    const double h = 1e-3 * std::max(1.0, std::abs(load.a[k]));
    plus.a[k] += h;
    minus.a[k] -= h;
    Eigen::VectorXd fp, fm;
    ElasticForce(body, test::Lvalue(Evaluate(body, c, frame)), &fp, nullptr, &plus);
    ElasticForce(body, test::Lvalue(Evaluate(body, c, frame)), &fm, nullptr, &minus);
    d_load_fd.col(k) = (fp - fm) / (2 * h);
  }
  EXPECT_LT((d_load - d_load_fd).norm(), 1e-8 * d_load.norm());
  Eigen::MatrixXd K_fd(n, n);
  for (int i = 0; i < n; ++i) {
    const double h = i < 6 * body.n_nodes() ? 1e-6 : 1e-6 * std::sqrt(se.mass_properties.mass);
    Eigen::VectorXd fs[2];
    for (int side = 0; side < 2; ++side) {
      BodyConfiguration p = c;
      const double e = side == 0 ? h : -h;
      if (i < 6 * body.n_nodes()) {
        const int a = i / 6, k = i % 6;
        if (k < 3)
          p.x[a][k] += e;
        else
          p.R[a] = ExpSO3(e * Eigen::Vector3d::Unit(k - 3)) * p.R[a];
      } else {
        p.eta[i - 6 * body.n_nodes()] += e;
      }
      const FrameSolution pf = SolveFrame(body, p, frame);
      ASSERT_TRUE(pf.ok);
      ElasticForce(body, test::Lvalue(Evaluate(body, p, pf)), &fs[side], nullptr, &load);
    }
    K_fd.col(i) = (fs[0] - fs[1]) / (2 * h);
  }
  EXPECT_LT((K - K_fd).norm(), 1e-6 * K.norm()) << "max |K - K_fd| " << (K - K_fd).cwiseAbs().maxCoeff();
}

// The stored tensors against closed forms for a 1 m tube with interfaces A (x = 0) and B
// (x = L), frame at A: the Craig-Bampton static mode of B's z translation (A and B's rotation held)
// is psi = 3 s^2 - 2 s^3, psi' = 6 (x - x^2) / L^2 (Euler-Bernoulli: a Timoshenko tube's shear
// parameter 12 EI / (k G A L^2) = 3e-3 changes the integrals by 0.4%).
//  - Basis stress (item 1): a unit stretch of B (uniform axial force EA / L) gives the geometric
//    stiffness EA / L int psi'^2 = 1.2 EA / L^2 on B_z: 2 A(B_x, p(B_z, B_z)).
//  - Inertia load (item 2): w_z^2 = 1 with both interfaces held: EA u'' = -rho A x, u(0) = u(L) =
//    0, N = rho A (L^2 / 6 - x^2 / 2); K_sigma(B_z, B_z) = int N psi'^2 = rho A 36 (1/180 - 1/210).
TEST(GeometricStiffening, StoredTensorsMatchTheClosedForms) {
  const Superelement se = Tube(4, true, "interface:A");
  ASSERT_TRUE(se.polynomial.has_value());
  EXPECT_FALSE(se.polynomial->cubic());
  const int n = se.n_reduced_dofs(), Bx = 6, Bz = 8;
  auto pair = [n](int j, int k) { return j * n - j * (j - 1) / 2 + (k - j); };
  const double EA = kE * kA, rhoA = kRho * kA;
  const double basis = 2 * se.polynomial->A(Bx, pair(Bz, Bz)), basis_expected = 1.2 * EA / (kL * kL);
  const double inertia = se.inertia_stiffness[8](Bz, Bz), inertia_expected = rhoA * 36 * (1.0 / 180 - 1.0 / 210);
  std::printf("[ info ] basis stress: %.6g (closed form %.6g); w_z^2 load case: %.6g (closed form %.6g)\n", basis,
              basis_expected, inertia, inertia_expected);
  EXPECT_NEAR(basis, basis_expected, 1e-6 * basis_expected);
  // The beam elements carry the axial force as its element mean (nonlinear_beam.h), exact at
  // the nodes for linear elements: sum_e N_mean,e int_e psi'^2 differs from the continuum by
  // O(h^2) (-0.22% with 40 elements); against that discrete value the tensor is exact.
  double discrete = 0.0;
  const int elements = 40;
  const double h = kL / elements, gp[2] = {-0.7745966692414834, 0.7745966692414834};
  auto u = [&](double x) { return rhoA / EA * (kL * kL * x / 6 - x * x * x / 6); };
  for (int e = 0; e < elements; ++e) {
    const double a = e * h, N_mean = EA * (u(a + h) - u(a)) / h;
    // int_e psi'^2 (a quartic): 3-point Gauss, exact.
    double integral = 0.0;
    for (double s : {gp[0], 0.0, gp[1]}) {
      const double x = a + 0.5 * h * (s + 1), weight = s == 0.0 ? 8.0 / 9 : 5.0 / 9;
      integral += 0.5 * h * weight * std::pow(6 * (x - x * x) / (kL * kL), 2);
    }
    discrete += N_mean * integral;
  }
  EXPECT_NEAR(inertia, discrete, 1e-6 * discrete);
  EXPECT_NEAR(inertia, inertia_expected, 3e-3 * inertia_expected);
  // The same in y (von Karman: both bending planes see the axial force).
  EXPECT_NEAR(se.inertia_stiffness[8](7, 7), discrete, 1e-6 * discrete);
  // A file without stiffening holds neither.
  const Superelement plain = Tube(4, false, "interface:A");
  EXPECT_FALSE(plain.polynomial.has_value());
  EXPECT_TRUE(plain.inertia_stiffness.empty());
}

// A clamped cantilever in ONE body under a tip tension T and a small lateral tip force F against
// the closed form of the tensioned cantilever, v = F / T (L - tanh(kL) / k), k = sqrt(T / EI):
// the tension is the stretch of B's static mode, its geometric stiffness the basis-stress term.
TEST(GeometricStiffening, TensionedCantileverInOneBodyMatchesTheClosedForm) {
  const double EI = kE * kI;
  for (double T : {2e3, 2e4}) {
    const double F = 10.0, k = std::sqrt(T / EI);
    const double expected = F / T * (kL - std::tanh(k * kL) / k);
    for (bool stiffening : {true, false}) {
      SystemModel model = test::ClampedOneBodyModel(Tube(4, stiffening), kL, Eigen::Vector3d(T, F, 0));
      StaticOptions options;
      options.steps = 5;
      SystemState state = InitialState(model);
      const StaticResult r = SolveStatic(model, state, options);
      ASSERT_TRUE(r.ok) << r.message;
      const double v = state.x[1].y();
      std::printf("[ info ] T = %.0f N, %s: tip deflection %.6e m, closed form %.6e (%+.3f%%)\n", T,
                  stiffening ? "with stiffening" : "without", v, expected, 100 * (v / expected - 1));
      if (stiffening) {
        EXPECT_NEAR(v, expected, 2e-3 * expected);
      }
    }
  }
}

// The basis-stress force is the gradient of W = eps^T K eps / 2, eps = q + K^+ A z
// (formats/reduced_polynomial.h): checked against central differences of W (force) and of the
// force (tangent, symmetric); W >= 0 at deformations where the Green-Lagrange energy cut after
// its cubic term is negative (the spurious softening the square removes); and the force agrees
// with the Green-Lagrange quadratic force to third order (the error falls 8x per halving).
TEST(GeometricStiffening, CondensedPolynomialIsABoundedEnergysGradient) {
  const Superelement se = Tube(4, true);
  ASSERT_TRUE(se.polynomial.has_value());
  const PolynomialStiffness p = WithCondensation(se.K, *se.polynomial);
  const int n = int(se.K.rows());
  auto cubic_energy = [&](const Eigen::VectorXd& q) { return 0.5 * q.dot(se.K * q) + q.dot(p.A * PairProducts(q)); };
  auto gradient = [&](const std::function<double(const Eigen::VectorXd&)>& W, const Eigen::VectorXd& q) {
    Eigen::VectorXd g(n);
    for (int i = 0; i < n; ++i) {
      const double h = 1e-6 * std::max(q.cwiseAbs().maxCoeff(), 1e-3);
      Eigen::VectorXd qp = q, qm = q;
      qp[i] += h;
      qm[i] -= h;
      g[i] = (W(qp) - W(qm)) / (2 * h);
    }
    return g;
  };
  // The local coordinates: 6 per interface node (metres, radians), then the modes; a deformed
  // state of the tube's size (tip 2 cm across 1 m, tip rotation 0.05 rad, a stretch of 1e-4).
  Eigen::VectorXd q = Eigen::VectorXd::Zero(n);
  q.segment<6>(0) << -5e-5, 0.0, 0.0, 0.0, 0.0, 0.01;
  q.segment<6>(6) << 5e-5, 0.02, -0.01, 0.002, 0.03, 0.05;
  for (int i = 12; i < n; ++i) q[i] = 0.003 * (i - 11);
  auto W = [&](const Eigen::VectorXd& x) { return PolynomialEnergy(se.K, p, x); };
  const Eigen::VectorXd f = PolynomialForce(se.K, p, q);
  const double force_error = (f - gradient(W, q)).norm() / f.norm();
  const Eigen::MatrixXd T = PolynomialTangent(se.K, p, q);
  Eigen::MatrixXd fd(n, n);
  for (int j = 0; j < n; ++j) {
    const double h = 1e-7 * std::max(std::abs(q[j]), 1e-2);
    Eigen::VectorXd qp = q, qm = q;
    qp[j] += h;
    qm[j] -= h;
    fd.col(j) = (PolynomialForce(se.K, p, qp) - PolynomialForce(se.K, p, qm)) / (2 * h);
  }
  const double tangent_error = (T - fd).norm() / T.norm();
  std::printf("[ info ] condensed polynomial: force vs dW/dq %.2e, tangent vs differences %.2e, asymmetry %.1e\n",
              force_error, tangent_error, (T - T.transpose()).norm() / T.norm());
  EXPECT_LT(force_error, 1e-6);
  EXPECT_LT(tangent_error, 1e-6);
  EXPECT_LT((T - T.transpose()).norm(), 1e-12 * T.norm());
  // Bounded below where the cubic energy is not: bend the tube and pull its ends together along
  // the shortening the bending asks for.
  int cubic_negative = 0;
  for (double scale : {0.5, 1.0, 2.0, 4.0}) {
    Eigen::VectorXd x = scale * q;
    x[6] = x[0] - 0.5 * std::pow(scale * 0.03, 2);  // B's axial coordinate: -L v'^2 / 2 of a 0.03 rad slope
    EXPECT_GE(W(x), 0.0) << "scale " << scale;
    cubic_negative += cubic_energy(x) < 0.0;
  }
  EXPECT_GT(cubic_negative, 0) << "the cubic energy should go negative somewhere in this family";
  // Third-order agreement with the Green-Lagrange quadratic force (gradient of the cubic energy).
  double previous = 0.0;
  for (double scale : {0.2, 0.1, 0.05}) {
    const Eigen::VectorXd x = scale * q;
    const double error = (PolynomialForce(se.K, p, x) - gradient(cubic_energy, x)).norm();
    if (previous > 0) {
      std::printf("[ info ] condensed vs cubic-energy force at %.2f q: ratio to the previous %.2f (third order: 8)\n",
                  scale, previous / error);
      EXPECT_GT(previous / error, 6.0);
    }
    previous = error;
  }
}

// A part whose basis is the six rigid motions (one interface node, no internal modes) has nothing
// to stiffen: asked for the stiffening, it reduces (it used to stop with "the polynomial internal
// force's linear part differs from K_r by 1": both are round-off) and stores none.
TEST(GeometricStiffening, RigidBasisReducesAndStoresNone) {
  const std::string yaml = test::StraightBeamYaml(0.3, 4, "{shape: circle, diameter: 0.01}",
                                                  "{E: 2.0e11, nu: 0.3, rho: 7800}", "[{name: A}]",
                                                  "reduction: {internal_modes: 0, geometric_stiffening: true, "
                                                  "floating_frame: 'interface:A'}\n");
  const ReduceResult r = ReducePart(ParsePart(yaml, "rigid.yaml"), nullptr);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_EQ(r.superelement.n_reduced_dofs(), 6);
  EXPECT_TRUE(r.superelement.inertia_stiffness.empty());
  EXPECT_FALSE(r.superelement.polynomial.has_value());
}

// The midpoint integrator's elastic force is no exact discrete gradient of the stiffened energy.
// So a stiffened file is used linear there unless the body asks (with a note either way), and
// with its stiffening under generalized-alpha; both take the file's exact inertia unless the
// body asks for the corotational one.
TEST(GeometricStiffening, MidpointUsesAStiffenedFileLinearUnlessAsked) {
  const std::string dir = ::testing::TempDir() + "stiffening_midpoint";
  std::filesystem::create_directories(dir);
  WriteSuperelementFile(Tube(2, true), dir + "/tube.h5");
  auto scene = [&](const std::string& integrator, const std::string& options) {
    const std::string path = dir + "/scene.yaml";
    std::ofstream(path) << "name: s\nunits: SI\nbodies:\n  - {name: tube, superelement: tube.h5, nodes: {A: a, B: b}"
                        << options << "}\njoints:\n  - {type: revolute, node: a, axis: [0, 0, 1]}\n"
                        << "analysis: {type: dynamic, end_time: 0.01, step: 1.0e-3, integrator: " << integrator
                        << "}\n";
    return BuildScene(ReadSceneFile(path));
  };
  auto noted = [](const Scene& s, const std::string& text) {
    for (const std::string& note : s.notes)
      if (note.find(text) != std::string::npos) return true;
    return false;
  };
  const Scene alpha = scene("generalized_alpha", "");
  EXPECT_TRUE(alpha.model.bodies[0].options().geometric_stiffening);
  const Scene midpoint = scene("midpoint", "");
  EXPECT_FALSE(midpoint.model.bodies[0].options().geometric_stiffening);
  EXPECT_TRUE(midpoint.model.bodies[0].has_exact_inertia());
  EXPECT_TRUE(alpha.model.bodies[0].has_exact_inertia());
  EXPECT_TRUE(noted(midpoint, "the file's geometric stiffening is not used"));
  const Scene forced = scene("midpoint", ", options: {geometric_stiffening: true}");
  EXPECT_TRUE(forced.model.bodies[0].options().geometric_stiffening);
  EXPECT_FALSE(noted(forced, "corotational"));
  const Scene corotational = scene("midpoint", ", options: {inertia: corotational}");
  EXPECT_FALSE(corotational.model.bodies[0].has_exact_inertia());
}

}  // namespace
}  // namespace femb
