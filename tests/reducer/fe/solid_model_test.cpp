// Solid parts end to end (gmsh TET10 mesh, RBE2 interfaces, Craig-Bampton): rigid-body modes
// and exact box mass properties; a slender cantilever bar against Euler-Bernoulli theory.
#include "reducer/fe/solid_model.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "reducer/reduction/craig_bampton.h"
#include "test_util.h"

namespace femb {
namespace {

std::string Bar(const std::string& interfaces, int modes, double h = 0.025,
                const std::string& elements = "tetrahedra") {
  return "name: bar\ntype: solid\nmaterial: {E: 2.1e11, nu: 0.3, rho: 7850}\n"
         "geometry: {shape: box, size: [1.0, 0.05, 0.05]}\n"
         "mesh: {size: " +
         std::to_string(h) + ", order: 2, elements: " + elements +
         "}\n"
         "interfaces: " +
         interfaces +
         "\n"
         "reduction: {internal_modes: " +
         std::to_string(modes) + ", floating_frame: center_of_mass}\n";
}

TEST(SolidModel, FreeFreeBoxHasSixRigidModesAndExactMassProperties) {
  const Superelement se = test::Reduce(Bar("[{name: root, group: xmin}, {name: tip, group: xmax}]", 4));
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(se.K, se.M);
  int rigid = 0;
  for (int k = 0; k < eig.eigenvalues().size(); ++k)
    rigid += std::abs(eig.eigenvalues()[k]) < 1e-8 * eig.eigenvalues().maxCoeff();
  EXPECT_EQ(rigid, 6);
  // Box 1 x 0.05 x 0.05 m: m = rho V, I_x = m (b^2 + h^2) / 12, I_y = I_z = m (L^2 + h^2) / 12.
  const double m = 7850 * 1.0 * 0.05 * 0.05;
  EXPECT_NEAR(se.mass_properties.mass, m, 1e-10 * m);
  EXPECT_LT((se.mass_properties.center_of_mass - Eigen::Vector3d(0.5, 0.025, 0.025)).norm(), 1e-10);
  const Eigen::Vector3d I(m * 0.005 / 12, m * 1.0025 / 12, m * 1.0025 / 12);
  EXPECT_LT((se.mass_properties.inertia_com - Eigen::Matrix3d(I.asDiagonal())).norm(), 1e-8 * I.norm());
  // The centre-of-mass frame interpolates rigid motions exactly.
  const Eigen::MatrixXd Phi_rig0 = RigidBodyModes(se, se.floating_frame.origin);
  EXPECT_LT((se.floating_frame.Phi_CB * Phi_rig0 - Eigen::MatrixXd::Identity(6, 6)).cwiseAbs().maxCoeff(), 1e-9);
  // The interface point is the centroid of its face's nodes: on the face, near its centre (the
  // unstructured mesh is not symmetric; element size 25 mm).
  EXPECT_NEAR(se.interfaces[1].position.x(), 1.0, 1e-12);
  EXPECT_LT((se.interfaces[1].position - Eigen::Vector3d(1.0, 0.025, 0.025)).norm(), 1e-3);
}

TEST(SolidModel, Hex20CantileverBarMatchesBeamTheoryWithin1Percent) {
  // The same bar in structured HEX20 (40 x 2 x 2 elements): mass exact, bending within 1% of
  // Timoshenko beam theory.
  const Superelement se = test::Reduce(Bar("[{name: root, group: xmin}]", 4, 0.025, "hexahedra"));
  EXPECT_EQ(se.provenance.element_type, "hex20");
  EXPECT_NEAR(se.mass_properties.mass, 7850 * 0.05 * 0.05, 1e-9 * 19.625);  // gmsh node positions to ~1e-10
  const Superelement beam = test::Reduce(
      test::StraightBeamYaml(1.0, 40, "{shape: rectangle, width: 0.05, height: 0.05}",
                             "{E: 2.1e11, nu: 0.3, rho: 7850}", "[{name: A}]", "reduction: {internal_modes: 4}\n"));
  std::printf("[ info ] cantilever HEX20: %.3f %.3f %.3f %.3f Hz; Timoshenko beam %.3f %.3f Hz\n",
              se.internal_frequencies_hz[0], se.internal_frequencies_hz[1], se.internal_frequencies_hz[2],
              se.internal_frequencies_hz[3], beam.internal_frequencies_hz[0], beam.internal_frequencies_hz[2]);
  for (int k = 0; k < 4; ++k) {
    const double ref = beam.internal_frequencies_hz[k];
    EXPECT_NEAR(se.internal_frequencies_hz[k], ref, 0.01 * ref) << k;
  }
}

TEST(SolidModel, CantileverBarMatchesBeamTheoryWithin1Percent) {
  // Clamped through a rigid (RBE2) root face: the fixed-interface modes are the cantilever's.
  // L/h = 20; Euler-Bernoulli f_n = (beta_n L)^2 / (2 pi L^2) sqrt(EI / rho A) for the first
  // mode; for the second, shear and rotary inertia already lower it by ~1%, so the reference is
  // Timoshenko beam theory (femb's beam element, checked against closed forms, 40 elements,
  // Cowper's shear factor for the square).
  const Superelement se = test::Reduce(Bar("[{name: root, group: xmin}]", 4));
  const double E = 2.1e11, rho = 7850, b = 0.05, L = 1.0, I = b * b * b * b / 12, A = b * b;
  const double f1 = 1.8751 * 1.8751 / (2 * M_PI * L * L) * std::sqrt(E * I / (rho * A));
  const double f2 = 4.6941 * 4.6941 / (2 * M_PI * L * L) * std::sqrt(E * I / (rho * A));
  std::printf("[ info ] cantilever TET10: %.3f %.3f %.3f %.3f Hz; Euler-Bernoulli %.3f, %.3f Hz\n",
              se.internal_frequencies_hz[0], se.internal_frequencies_hz[1], se.internal_frequencies_hz[2],
              se.internal_frequencies_hz[3], f1, f2);
  const Superelement beam = test::Reduce(test::StraightBeamYaml(L, 40, "{shape: rectangle, width: 0.05, height: 0.05}",
                                                                "{E: 2.1e11, nu: 0.3, rho: 7850}", "[{name: A}]",
                                                                "reduction: {internal_modes: 4}\n"));
  std::printf("[ info ] Timoshenko beam: %.3f %.3f Hz\n", beam.internal_frequencies_hz[0],
              beam.internal_frequencies_hz[2]);
  for (int k = 0; k < 2; ++k) EXPECT_NEAR(se.internal_frequencies_hz[k], f1, 0.01 * f1) << k;
  for (int k = 0; k < 4; ++k) {
    const double ref = beam.internal_frequencies_hz[k];
    EXPECT_NEAR(se.internal_frequencies_hz[k], ref, 0.01 * ref) << k;
  }
}

TEST(SolidModel, Rbe2IsStifferThanRbe3) {
  // Clamp the root (RBE2), couple the tip face by RBE2 or RBE3 and compare the static tip
  // compliance (the reduced K of the tip node with the root clamped: exact statics).
  auto tip_compliance = [](const std::string& coupling) {
    const Superelement se =
        test::Reduce(Bar("[{name: root, group: xmin}, {name: tip, group: xmax, coupling: " + coupling + "}]", 0),
                     {"reduction.full_modes=8"});
    const Eigen::MatrixXd K_tip = se.K.block(6, 6, 6, 6);
    return std::make_pair(Eigen::MatrixXd(K_tip.inverse()), se.full_free_free_frequencies_hz);
  };
  const auto [C2, f2] = tip_compliance("rbe2");
  const auto [C3, f3] = tip_compliance("rbe3");
  // Rigid coupling constrains the face: smaller compliance in every direction, the difference
  // positive semi-definite, and every free-free frequency at least as high (interlacing).
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> diff(0.5 * (C3 - C2 + (C3 - C2).transpose()));
  EXPECT_GT(diff.eigenvalues().minCoeff(), -1e-9 * C3.norm());
  for (int i = 0; i < 6; ++i) EXPECT_LE(C2(i, i), C3(i, i) * (1 + 1e-12)) << i;
  for (int k = 6; k < f2.size(); ++k) EXPECT_GE(f2[k], f3[k] * (1 - 1e-9)) << k;
  // Both tip deflections near Timoshenko beam theory: PL^3/3EI + PL/(kGA).
  const double E = 2.1e11, G = E / 2.6, b = 0.05, I = b * b * b * b / 12, k = 10 * 1.3 / (12 + 11 * 0.3);
  const double beam = 1.0 / (3 * E * I) + 1.0 / (k * G * b * b);
  std::printf("[ info ] tip compliance u_y: RBE2 %.6e, RBE3 %.6e, beam theory %.6e m/N\n", C2(1, 1), C3(1, 1), beam);
  EXPECT_NEAR(C2(1, 1), beam, 0.01 * beam);
  EXPECT_NEAR(C3(1, 1), beam, 0.01 * beam);
}

// Built-in cylinder and tube (curved TET10 faces): 6 rigid-body modes, and mass and inertia
// against the closed forms of the exact geometry within 0.5% (the mesh approximates the circle).
TEST(SolidModel, CylinderAndTubeHaveTheMassPropertiesOfTheirGeometry) {
  const double R = 0.05, r = 0.03, L = 0.3, rho = 7850;
  for (const bool tube : {false, true}) {
    const std::string part = std::string("name: c\ntype: solid\nmaterial: {E: 2.1e11, nu: 0.3, rho: 7850}\n") +
                             "geometry: {shape: " + (tube ? "tube" : "cylinder") + ", radius: 0.05, length: 0.3" +
                             (tube ? ", inner_radius: 0.03}" : "}") + "\nmesh: {size: 0.015, order: 2}\n" +
                             "interfaces: [{name: a, group: " + (tube ? "outer" : "bottom") +
                             "}, {name: b, group: " + (tube ? "inner" : "top") +
                             ", coupling: rbe3}]\nreduction: {internal_modes: 2, floating_frame: " +
                             (tube ? "mean_axes" : "center_of_mass") + "}\n";
    const Superelement se = test::Reduce(part);
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(se.K, se.M);
    int rigid = 0;
    for (int k = 0; k < eig.eigenvalues().size(); ++k)
      rigid += std::abs(eig.eigenvalues()[k]) < 1e-8 * eig.eigenvalues().maxCoeff();
    EXPECT_EQ(rigid, 6);
    const double ri = tube ? r : 0.0;
    const double m = rho * M_PI * (R * R - ri * ri) * L;
    const double Izz = m * (R * R + ri * ri) / 2, Ixx = m * (3 * (R * R + ri * ri) + L * L) / 12;
    std::printf("[ info ] %s: mass %.6f kg (exact %.6f), Izz %.6e (exact %.6e)\n", tube ? "tube" : "cylinder",
                se.mass_properties.mass, m, se.mass_properties.inertia_com(2, 2), Izz);
    EXPECT_NEAR(se.mass_properties.mass, m, 5e-3 * m);
    EXPECT_NEAR(se.mass_properties.inertia_com(2, 2), Izz, 5e-3 * Izz);
    EXPECT_NEAR(se.mass_properties.inertia_com(0, 0), Ixx, 5e-3 * Ixx);
    EXPECT_NEAR(se.mass_properties.inertia_com(1, 1), Ixx, 5e-3 * Ixx);
    EXPECT_LT((se.mass_properties.center_of_mass - Eigen::Vector3d(0, 0, L / 2)).norm(), 1e-3 * L);
    // The interface points are the area-weighted centroids of their surfaces: on the axis (the
    // bottom face centre of the cylinder; the bore's axis), to the faceting of the curved surface
    // (the plain mean of the unstructured nodes was up to 1.5 mm off, a tenth of an element).
    std::printf("[ info ] %s: interface points off the axis by %.2e, %.2e m\n", tube ? "tube" : "cylinder",
                se.interfaces[0].position.head<2>().norm(), se.interfaces[1].position.head<2>().norm());
    EXPECT_LT(se.interfaces[0].position.head<2>().norm(), 1e-4);
    EXPECT_LT(se.interfaces[1].position.head<2>().norm(), 1e-4);
    if (!tube) {
      EXPECT_LT(std::abs(se.interfaces[0].position.z()), 1e-9);
    }
  }
}

// Every interface distributing (RBE3): K_ii keeps its rigid-body modes, so the reduction
// factors K_ii + a W_1^T W_1, equal to K_ii on the constraint space. The interface coordinates are the
// constraints W u = q exactly; the reduced model has 6 rigid-body modes and its free-free
// frequencies are Rayleigh-Ritz upper bounds of the full model's, within 1% for the first four.
TEST(SolidModel, AllDistributingInterfacesReduceThroughAnAugmentedFactor) {
  const PartSpec part =
      ParsePart(Bar("[{name: root, group: xmin, coupling: rbe3}, {name: tip, group: xmax, coupling: rbe3}]", 8) + "",
                "test.yaml", {"reduction.full_modes=10"});
  const FeModel model = BuildSolidModel(part);
  ASSERT_EQ(model.interface_weights.size(), 2u);
  ASSERT_EQ(model.interface_weights[0].rows(), 6);
  const CraigBamptonResult cb = CraigBamptonReduce(model, 8, nullptr);
  ASSERT_TRUE(cb.ok) << cb.message;
  for (int k = 0; k < 2; ++k) {
    const Eigen::MatrixXd q = model.interface_weights[k] * cb.shapes;  // 6 x n_r
    Eigen::MatrixXd expected = Eigen::MatrixXd::Zero(6, cb.shapes.cols());
    expected.block(0, 6 * k, 6, 6).setIdentity();
    EXPECT_LT((q - expected).cwiseAbs().maxCoeff(), 1e-10) << "interface " << k;
  }
  const Superelement se =
      test::Reduce(Bar("[{name: root, group: xmin, coupling: rbe3}, {name: tip, group: xmax, coupling: rbe3}]", 8),
                   {"reduction.full_modes=10"});
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(se.K, se.M);
  int rigid = 0;
  for (int k = 0; k < eig.eigenvalues().size(); ++k)
    rigid += std::abs(eig.eigenvalues()[k]) < 1e-8 * eig.eigenvalues().maxCoeff();
  EXPECT_EQ(rigid, 6);
  for (int k = 6; k < 10; ++k) {
    const double reduced = std::sqrt(eig.eigenvalues()[k]) / (2 * M_PI), full = se.full_free_free_frequencies_hz[k];
    EXPECT_GE(reduced, full * (1 - 1e-9)) << k;
    EXPECT_LT(reduced, 1.01 * full) << k;
  }
}

// The all-RBE3 reduction at any scale of part (it once failed for a 0.1 m connecting rod and for
// boxes of 0.01-10 m: a shift of K_ii + s M_ii chosen from the mesh's largest K/M ratio did not
// converge): the same structured box scaled by L from 0.01 m to 10 m reduces, and its reduced
// free-free frequencies times L agree to 1e-7 (f ~ 1/L for equal E, rho and shape), with 6
// rigid-body modes and the interface constraints W Phi = 1 to 1e-10 at every scale (rotations
// measured as L theta).
TEST(SolidModel, AllDistributingInterfacesReduceAtAnyScale) {
  Eigen::VectorXd reference;
  for (const double L : {0.01, 0.1, 1.0, 10.0}) {
    char text[512];
    std::snprintf(
        text, sizeof text,
        "name: box\ntype: solid\nmaterial: {E: 1.0e11, nu: 0.3, rho: 7850}\n"
        "geometry: {shape: box, size: [%.17g, %.17g, %.17g]}\nmesh: {size: %.17g, order: 2, elements: hexahedra}\n"
        "interfaces: [{name: A, group: xmin, coupling: rbe3}, {name: B, group: xmax, coupling: rbe3}]\n"
        "reduction: {internal_modes: 4}\n",
        L, 0.2 * L, 0.2 * L, 0.1 * L);
    const PartSpec part = ParsePart(text, "box.yaml", {});
    const FeModel model = BuildSolidModel(part);
    const CraigBamptonResult cb = CraigBamptonReduce(model, 4, nullptr);
    ASSERT_TRUE(cb.ok) << "L = " << L << ": " << cb.message;
    // Dimensionless: rotations measured as L theta (rows) and rotation coordinates per 1/L (columns).
    Eigen::VectorXd row_scale = Eigen::VectorXd::Ones(6), col_scale = Eigen::VectorXd::Ones(cb.shapes.cols());
    row_scale.tail(3).setConstant(L);
    for (int c = 0; c < 12; ++c) col_scale[c] = c % 6 >= 3 ? 1.0 / L : 1.0;
    for (int k = 0; k < 2; ++k) {
      const Eigen::MatrixXd q = model.interface_weights[k] * cb.shapes;
      Eigen::MatrixXd expected = Eigen::MatrixXd::Zero(6, cb.shapes.cols());
      expected.block(0, 6 * k, 6, 6).setIdentity();
      const Eigen::MatrixXd error = row_scale.asDiagonal() * (q - expected) * col_scale.asDiagonal();
      EXPECT_LT(error.cwiseAbs().maxCoeff(), 1e-10) << "L = " << L << ", interface " << k;
    }
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(cb.K, cb.M);
    const Eigen::VectorXd lambda = eig.eigenvalues();
    int rigid = 0;
    for (int k = 0; k < lambda.size(); ++k) rigid += std::abs(lambda[k]) < 1e-8 * lambda.maxCoeff();
    EXPECT_EQ(rigid, 6) << "L = " << L;
    const Eigen::VectorXd fL = lambda.tail(lambda.size() - 6).cwiseSqrt() * L;
    if (reference.size() == 0) {
      reference = fL;
    } else {
      EXPECT_LT((fL - reference).cwiseAbs().maxCoeff() / reference.maxCoeff(), 1e-7) << "L = " << L;
    }
  }
}

// A flat face's interface point is its centre exactly, whatever the unstructured mesh (the plain
// mean of its nodes was 0.22 mm off the 50 mm face's centre, which made a revolute joint to a
// beam placed at the face centre a 0.22 mm gap).
TEST(SolidModel, InterfacePointIsTheFaceCentroid) {
  const Superelement se = test::Reduce(Bar("[{name: root, group: xmin}, {name: tip, group: xmax}]", 2));
  EXPECT_LT((se.interfaces[0].position - Eigen::Vector3d(0, 0.025, 0.025)).norm(), 1e-12);
  EXPECT_LT((se.interfaces[1].position - Eigen::Vector3d(1, 0.025, 0.025)).norm(), 1e-12);
}

TEST(SolidModel, MissingNodeSetIsNamed) {
  const std::string message = test::ThrownMessage([] { test::Reduce(Bar("[{name: root, group: xlow}]", 2)); });
  EXPECT_NE(message.find("interface 'root': node set 'xlow' not found in the mesh (known: xmax, xmin, ymax, ymin, "
                         "zmax, zmin; or pick the nodes by geometry with 'select')"),
            std::string::npos)
      << message;
}

// Interfaces picked by geometry take the same nodes as the named sets of the same
// mesh: the reduced matrices agree to round-off. Tube 50/30 mm x 0.3 m: the bore (cylinder of
// radius 30 mm, bounded to the tube's length), the bottom face (plane z = 0) and the top face
// (a box around z = 0.3); also a sphere cap on a box's corner.
TEST(SolidModel, GeometricSelectionsTakeTheNodesOfTheNamedSets) {
  const std::string head =
      "name: t\ntype: solid\nmaterial: {E: 2.1e11, nu: 0.3, rho: 7850}\n"
      "geometry: {shape: tube, radius: 0.05, inner_radius: 0.03, length: 0.3}\n"
      "mesh: {size: 0.02, order: 2}\nreduction: {internal_modes: 3, floating_frame: mean_axes}\n";
  // The bore shares its edge nodes with the end faces: two models.
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"[{name: bore, group: inner, coupling: rbe3}]",
       "[{name: bore, coupling: rbe3, select: {cylinder: {point: [0, 0, 0], axis: [0, 0, 2], radius: 0.03, length: "
       "0.3}}}]"},
      {"[{name: bottom, group: bottom}, {name: top, group: top}]",
       "[{name: bottom, select: {plane: {point: [0, 0, 0], normal: [0, 0, -1]}, tolerance: 1e-6}},"
       " {name: top, select: {box: {min: [-1, -1, 0.2999], max: [1, 1, 0.31]}}}]"}};
  for (const auto& [named, picked] : cases) {
    const Superelement by_name = test::Reduce(head + "interfaces: " + named + "\n");
    const Superelement by_geometry = test::Reduce(head + "interfaces: " + picked + "\n");
    ASSERT_EQ(by_name.K.rows(), by_geometry.K.rows());
    const double k_diff = (by_name.K - by_geometry.K).norm() / by_name.K.norm();
    const double m_diff = (by_name.M - by_geometry.M).norm() / by_name.M.norm();
    std::printf("[ info ] tube by name vs by geometry: K %.2e, M %.2e\n", k_diff, m_diff);
    EXPECT_LT(k_diff, 1e-10);
    EXPECT_LT(m_diff, 1e-10);
    for (size_t k = 0; k < by_name.interfaces.size(); ++k)
      EXPECT_LT((by_name.interfaces[k].position - by_geometry.interfaces[k].position).norm(), 1e-12);
  }
}

TEST(SolidModel, SelectionSphereAndBadSelectionsAreNamed) {
  PartSpec part =
      ParsePart(Bar("[{name: corner, select: {sphere: {center: [1, 0.05, 0.05], radius: 0.02}, tolerance: 0.02}}]", 2),
                "bar.yaml");
  // Every node within 0.04 of the corner (the sphere's surface +- 0.02 includes the inside).
  const FeModel model = BuildSolidModel(part);
  int expected = 0;
  for (Eigen::Index i = 0; i < model.nodes.rows(); ++i)
    expected += (model.nodes.row(i) - Eigen::RowVector3d(1, 0.05, 0.05)).norm() <= 0.04;
  EXPECT_GT(expected, 3);
  EXPECT_EQ(model.interface_dofs.size(), 1u);
  EXPECT_EQ(model.n_dofs(), 3 * (model.n_nodes() - expected) + 6);
  // No node on the surface: the nearest node's distance and the tolerance are named (a part in
  // mm-sized numbers while the mesh is in m).
  std::string message = test::ThrownMessage(
      [] { test::Reduce(Bar("[{name: root, select: {plane: {point: [-20, 0, 0], normal: [1, 0, 0]}}}]", 2)); });
  EXPECT_NE(
      message.find(
          "test.yaml:6: interfaces[0].select: interface 'root': the plane through (-20, 0, 0) normal to (1, 0, 0) "
          "selects no node: the nearest of the"),
      std::string::npos)
      << message;
  EXPECT_NE(message.find("is 20 from it, the tolerance is 0.0001"), std::string::npos) << message;
  // Two selections sharing nodes.
  message = test::ThrownMessage([] {
    test::Reduce(
        Bar("[{name: a, group: xmin}, {name: b, select: {box: {min: [0, 0, 0], max: [0.1, 0.05, 0.05]}}}]", 2));
  });
  EXPECT_NE(message.find("interface 'b': the box selection shares nodes with interface 'a'"), std::string::npos)
      << message;
  // Both or neither of group and select.
  message = test::ThrownMessage(
      [] { test::Reduce(Bar("[{name: a, group: xmin, select: {plane: {point: [0, 0, 0], normal: [1, 0, 0]}}}]", 2)); });
  EXPECT_NE(message.find("give either 'group'"), std::string::npos) << message;
  message = test::ThrownMessage(
      [] { test::Reduce(Bar("[{name: a, select: {plane: {point: [0, 0, 0], normal: [0, 0, 0]}}}]", 2)); });
  EXPECT_NE(message.find("normal: must be a nonzero vector"), std::string::npos) << message;
}

// The reduction that holds the model's K and M only as their blocks while the factor lives (the
// mutable model's overload) gives the same numbers to the bit as the one that leaves the model
// alone, and gives K and M back with the same entries: with an RBE2 and an RBE3 interface (the
// boundary DOFs and the constraint rows), the inertia load cases (their loads taken before K and M
// are released) and a factor refused under a memory limit (K and M given back on that way out
// too).
TEST(SolidModel, ReductionHoldingTheMatricesAsBlocksGivesTheSameNumbers) {
  const PartSpec part =
      ParsePart(Bar("[{name: root, group: xmin, coupling: rbe2}, {name: tip, group: xmax, coupling: rbe3}]", 6, 0.05),
                "test.yaml");
  const FeModel kept = BuildSolidModel(part);
  const Eigen::MatrixXd fields = InertiaFields(kept);
  const CraigBamptonResult a = CraigBamptonReduce(kept, 6, nullptr, 200, 0, nullptr, &fields);
  ASSERT_TRUE(a.ok) << a.message;
  FeModel model = kept;
  const CraigBamptonResult b = CraigBamptonReduce(model, 6, nullptr, 200, 0, nullptr, &fields);
  ASSERT_TRUE(b.ok) << b.message;
  const auto same = [](const SparseMatrix& x, const SparseMatrix& y) {
    return x.rows() == y.rows() && x.nonZeros() == y.nonZeros() && x.isCompressed() && y.isCompressed() &&
           std::equal(x.outerIndexPtr(), x.outerIndexPtr() + x.outerSize() + 1, y.outerIndexPtr()) &&
           std::equal(x.innerIndexPtr(), x.innerIndexPtr() + x.nonZeros(), y.innerIndexPtr()) &&
           std::equal(x.valuePtr(), x.valuePtr() + x.nonZeros(), y.valuePtr());
  };
  EXPECT_TRUE(same(model.K, kept.K));
  EXPECT_TRUE(same(model.M, kept.M));
  EXPECT_EQ((a.K - b.K).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ((a.M - b.M).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ((a.shapes - b.shapes).cwiseAbs().maxCoeff(), 0.0);
  ASSERT_EQ(b.inertia_displacements.cols(), 12);
  EXPECT_EQ((a.inertia_displacements - b.inertia_displacements).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_GT(b.inertia_displacements.cwiseAbs().maxCoeff(), 0.0);
  const CraigBamptonResult refused = CraigBamptonReduce(model, 6, nullptr, 200, 1.0);
  EXPECT_TRUE(refused.factorization.too_big);
  EXPECT_TRUE(same(model.K, kept.K));
  EXPECT_TRUE(same(model.M, kept.M));
}

}  // namespace
}  // namespace femb
