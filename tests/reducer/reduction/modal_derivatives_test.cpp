// Modal derivatives of a solid leaf spring (thesis 8.3): the second-order static response of the
// full nonlinear model to a sideways motion of one end lies in the span of the Craig-Bampton basis
// augmented with the derivative of that end's static mode, and far outside the plain basis; the
// derivatives vanish at the interfaces and are M-orthonormal to the internal modes; the thin
// leaf keeps Phi_CB Phi_rig0 = 1; bad pairs are refused with the part file named.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>

#include "formats/reduced_polynomial.h"
#include "formats/superelement_file.h"
#include "reducer/fe/nonlinear_solid.h"
#include "reducer/fe/solid_model.h"
#include "reducer/reduce_part.h"
#include "test_util.h"

namespace femb {
namespace {

// Steel leaf 50 x 10 x 0.5 mm, structured HEX20 (25 x 5 x 1), RBE2 ends A (x = 0) and B.
std::string Leaf(const std::string& derivatives) {
  return "name: leaf\ntype: solid\nmaterial: {E: 2.1e11, nu: 0.3, rho: 7850}\n"
         "geometry: {shape: box, size: [0.05, 0.01, 0.0005]}\n"
         "mesh: {size: 0.002, order: 2, elements: hexahedra}\n"
         "interfaces: [{name: A, group: xmin}, {name: B, group: xmax}]\n"
         "reduction: {internal_modes: 4, floating_frame: center_of_mass" +
         derivatives + "}\n";
}

// Relative distance of x from the column span of V (least squares).
double OutOfSpan(const Eigen::MatrixXd& V, const Eigen::VectorXd& x) {
  const Eigen::VectorXd c = V.colPivHouseholderQr().solve(x);
  return (V * c - x).norm() / x.norm();
}

TEST(ModalDerivatives, SecondOrderStaticResponseLiesInTheAugmentedBasis) {
  // B moved across the thickness (z) by +-delta with A clamped and B's
  // other coordinates held: u(delta) = delta psi + delta^2 theta / 2 + O(delta^3), so the even part
  // (u(delta) + u(-delta)) / 2 is delta^2 theta / 2 + O(delta^4): the membrane stretch that
  // the linear basis lacks. Reference: femb's full Newton on the same mesh (SolveNonlinearStatic).
  const PartSpec part = ParsePart(Leaf(", modal_derivatives: {pairs: [[8, 8]]}"), "leaf.yaml");
  const ReduceResult with = ReducePart(part, nullptr);
  ASSERT_TRUE(with.ok) << with.message;
  const Superelement& se = with.superelement;
  ASSERT_EQ(se.n_modal_derivatives, 1);
  EXPECT_EQ(se.modal_derivative_pairs[0], std::make_pair(8, 8));
  EXPECT_EQ(ReducedCoordinateLabel(se, 16), "derivative 1 (B.u_z x B.u_z)");
  ASSERT_TRUE(se.visualization.has_value());
  const Eigen::MatrixXd& V = se.visualization->shapes;  // mesh DOFs x 17

  const FeModel model = BuildSolidModel(part);
  const SvkSolidMesh solid(SolidType::kHex20, model.nodes, model.cells, part.material);
  std::vector<int> held;
  for (int k = 0; k < 2; ++k)
    for (int d = 0; d < 6; ++d) held.push_back(model.interface_dofs[k][d].value);
  // The part outside the augmented basis is the O(delta^4) remainder: relative to the even part
  // (~delta^2) it must shrink as delta^2. delta = 0.5 and 0.25 mm (1 and 0.5 thicknesses).
  auto outside = [&](double delta, double* plain) {
    Eigen::VectorXd even = Eigen::VectorXd::Zero(model.n_dofs());
    for (double sign : {1.0, -1.0}) {
      Eigen::VectorXd values = Eigen::VectorXd::Zero(12);
      values[8] = sign * delta;  // B.u_z
      const NonlinearStaticResult r =
          SolveNonlinearStatic(solid, model.mesh_map, held, values, Eigen::VectorXd::Zero(model.n_dofs()), 4);
      EXPECT_TRUE(r.converged) << r.message;
      even += 0.5 * r.u.back();
    }
    const Eigen::VectorXd even_mesh = model.mesh_map * even;
    *plain = OutOfSpan(V.leftCols(16), even_mesh);
    return OutOfSpan(V, even_mesh);
  };
  double plain_coarse = 0, plain_fine = 0;
  const double coarse = outside(5e-4, &plain_coarse), fine = outside(2.5e-4, &plain_fine);
  std::printf(
      "[ info ] even part of the response outside the basis, delta = 0.5 / 0.25 mm: with the derivative "
      "%.2e / %.2e (ratio %.2f), without %.2e / %.2e\n",
      coarse, fine, coarse / fine, plain_coarse, plain_fine);
  EXPECT_LT(fine, 0.01);
  EXPECT_GT(coarse / fine, 3.0);  // second order: 4 in the limit
  EXPECT_LT(coarse / fine, 5.0);
  EXPECT_GT(plain_fine, 0.5);  // the plain Craig-Bampton basis misses the stretch entirely
}

TEST(ModalDerivatives, VanishAtTheInterfacesAndAreMOrthonormalToTheModes) {
  const ReduceResult r = ReducePart(ParsePart(Leaf(", modal_derivatives: {of: static}"), "leaf.yaml"), nullptr);
  ASSERT_TRUE(r.ok) << r.message;
  const Superelement& se = r.superelement;
  const int n_cb = se.n_interface_dofs() + se.n_internal_modes(), d = int(se.n_modal_derivatives);
  std::printf("[ info ] %d of 78 static-mode pairs kept\n", d);
  ASSERT_GT(d, 0);
  // Reduced mass: the derivative block is the identity, orthogonal to the internal modes.
  const Eigen::MatrixXd Mdd = se.M.bottomRightCorner(d, d);
  EXPECT_LT((Mdd - Eigen::MatrixXd::Identity(d, d)).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_LT(se.M.block(se.n_interface_dofs(), n_cb, se.n_internal_modes(), d).cwiseAbs().maxCoeff(), 1e-10);
  // Zero at the interfaces: the reduced rows of the static coordinates have no derivative part in
  // the rigid-body modes, and the mesh shapes vanish on the end faces (x = 0 and x = 0.05).
  const Visualization& v = *se.visualization;
  double at_ends = 0, scale = 0;
  for (long node = 0; node < v.nodes.rows(); ++node) {
    const double x = v.nodes(node, 0);
    for (int k = n_cb; k < n_cb + d; ++k) {
      const double u = v.shapes.block(3 * node, k, 3, 1).norm();
      scale = std::max(scale, u);
      if (x < 1e-9 || x > 0.05 - 1e-9) at_ends = std::max(at_ends, u);
    }
  }
  EXPECT_LT(at_ends, 1e-12 * scale);
  // The thin leaf (K_ii condition ~1e10) still reproduces rigid motions exactly: the static
  // modes are corrected for it (craig_bampton.cpp); before, Phi_CB Phi_rig0 - 1 was 3e-8.
  const Eigen::MatrixXd Phi_rig0 = RigidBodyModes(se, se.floating_frame.origin);
  EXPECT_LT((se.floating_frame.Phi_CB * Phi_rig0 - Eigen::MatrixXd::Identity(6, 6)).cwiseAbs().maxCoeff(), 1e-10);
}

TEST(ModalDerivatives, ReducedPolynomialForceIsTheProjectedFullForce) {
  // f_r(q) = V^T f(V q) exactly (a cubic polynomial), for q with displacements up to ~2
  // thicknesses; its tangent against central differences; a file round trip keeps A and B.
  const PartSpec part = ParsePart(Leaf(", modal_derivatives: {pairs: [[8, 8], [8, 12], [12, 12]]}"), "leaf.yaml");
  const ReduceResult r = ReducePart(part, nullptr);
  ASSERT_TRUE(r.ok) << r.message;
  const Superelement& se = r.superelement;
  ASSERT_TRUE(se.polynomial.has_value());
  const int n = se.n_reduced_dofs();
  EXPECT_EQ(se.polynomial->A.cols(), n * (n + 1) / 2);
  const FeModel model = BuildSolidModel(part);
  const SvkSolidMesh solid(SolidType::kHex20, model.nodes, model.cells, part.material);
  const Eigen::MatrixXd& V = se.visualization->shapes;
  Eigen::VectorXd q = Eigen::VectorXd::Zero(n);
  q[8] = 1e-3;   // B.u_z: 2 thicknesses
  q[7] = -2e-4;  // B.u_y
  q[12] = 3e-4;  // mode 1 (mass-normalized: ~1 mm of displacement per 1e-3)
  for (int k = 16; k < n; ++k) q[k] = 1e-4 * (k - 15);
  const Eigen::VectorXd direct = V.transpose() * solid.Force(V * q);
  const Eigen::VectorXd poly = PolynomialForce(se.K, *se.polynomial, q);
  const double linear_part = (se.K * q - direct).norm() / direct.norm();
  const double err = (poly - direct).norm() / direct.norm();
  std::printf("[ info ] reduced force: polynomial vs projected full force %.2e (linear part alone off by %.2e)\n", err,
              linear_part);
  EXPECT_LT(err, 1e-9);
  EXPECT_GT(linear_part, 1e-2);  // the case is nonlinear enough for the check to mean something
  EXPECT_NEAR(PolynomialEnergy(se.K, *se.polynomial, q), solid.Energy(V * q), 1e-9 * solid.Energy(V * q));
  const Eigen::MatrixXd T = PolynomialTangent(se.K, *se.polynomial, q);
  Eigen::MatrixXd fd(n, n);
  for (int i = 0; i < n; ++i) {
    const double h = 1e-7;
    Eigen::VectorXd qp = q, qm = q;
    qp[i] += h;
    qm[i] -= h;
    fd.col(i) = (PolynomialForce(se.K, *se.polynomial, qp) - PolynomialForce(se.K, *se.polynomial, qm)) / (2 * h);
  }
  EXPECT_LT((fd - T).norm(), 1e-6 * T.norm());
  const std::string path = ::testing::TempDir() + "leaf_poly.h5";
  WriteSuperelementFile(se, path);
  const Superelement back = ReadSuperelementFile(path);
  ASSERT_TRUE(back.polynomial.has_value());
  EXPECT_EQ(back.polynomial->A, se.polynomial->A);
  EXPECT_EQ(back.polynomial->B, se.polynomial->B);
}

// The polynomial energy at q with the coordinates from `first` on (internal modes, derivatives)
// at their equilibrium (Newton on the polynomial's force and tangent).
double RelaxedEnergy(const Eigen::MatrixXd& K, const PolynomialStiffness& p, Eigen::VectorXd q, int first) {
  const long m = q.size() - first;
  for (int it = 0; it < 20; ++it) {
    const Eigen::VectorXd f = PolynomialForce(K, p, q).tail(m);
    const Eigen::VectorXd dq = PolynomialTangent(K, p, q).bottomRightCorner(m, m).ldlt().solve(f);
    q.tail(m) -= dq;
    if (dq.norm() <= 1e-14 * std::max(q.norm(), 1e-300)) break;
  }
  return PolynomialEnergy(K, p, q);
}

TEST(ModalDerivatives, FiniteRigidRotationCostsNoStrainEnergyWithTheRotationCompletion) {
  // Local coordinates of the whole leaf turned rigidly by theta about y (interfaces at X_k from
  // the frame origin): u_k = (R - 1) X_k, theta_k = theta e_y, the internal coordinates at their
  // equilibrium. The linear static modes move the faces by theta x r only, which Green-Lagrange
  // reads as a stretch theta^2 / 2; the second-order completion of the face rotation
  // (nonlinear_solid.h) removes it to higher order. (Made K-orthogonal to the internal modes and
  // derivatives, the completion leaves a second-order field V a theta^2 of theirs: at modes 0 the
  // energy is 0.62 of the linear faces', and the internal coordinates take it up.)
  const PartSpec part = ParsePart(Leaf(", modal_derivatives: {pairs: [[8, 8]]}"), "leaf.yaml");
  const ReduceResult r = ReducePart(part, nullptr);
  ASSERT_TRUE(r.ok) << r.message;
  const Superelement& se = r.superelement;
  const FeModel model = BuildSolidModel(part);
  const SvkSolidMesh solid(SolidType::kHex20, model.nodes, model.cells, part.material);
  const Eigen::MatrixXd& V = se.visualization->shapes;
  const ReducedPolynomial plain = ReduceSvk(solid, V);  // without the completion
  std::vector<Eigen::Vector3d> points;
  for (const InterfaceNode& node : se.interfaces) points.push_back(node.position);
  PolynomialRequest request;
  request.static_coordinates = 12;
  const ReducedPolynomial completed = ReduceSvk(
      solid, V, InterfaceRotationCompletion(se.visualization->nodes, V, points, se.floating_frame.origin), request);
  EXPECT_LT((completed.B - se.polynomial->B).norm(), 1e-12 * completed.B.norm());  // what the reducer stored
  const PolynomialStiffness without{plain.A, plain.B, Eigen::MatrixXd()};
  const int n = se.n_reduced_dofs();
  for (double theta : {0.05, 0.1}) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitY()).toRotationMatrix();
    Eigen::VectorXd q = Eigen::VectorXd::Zero(n);
    for (int k = 0; k < 2; ++k) {
      const Eigen::Vector3d X = se.interfaces[size_t(k)].position - se.floating_frame.origin;
      q.segment<3>(6 * k) = (R - Eigen::Matrix3d::Identity()) * X;
      q[6 * k + 4] = theta;
    }
    // Reference scale: the energy of bending the leaf to that end rotation, K q for the rotation
    // coordinates of one end alone.
    Eigen::VectorXd bend = Eigen::VectorXd::Zero(n);
    bend[10] = theta;
    const double scale = 0.5 * bend.dot(se.K * bend);
    const double with_completion = RelaxedEnergy(se.K, *se.polynomial, q, 12) / scale;
    const double linear_faces = RelaxedEnergy(se.K, without, q, 12) / scale;
    std::printf(
        "[ info ] rigid rotation %.2f rad: strain energy / bending energy %.2e with the completion, %.2e without "
        "(modes 0: %.2e, %.2e)\n",
        theta, with_completion, linear_faces, PolynomialEnergy(se.K, *se.polynomial, q) / scale,
        PolynomialEnergy(se.K, without, q) / scale);
    EXPECT_LT(std::abs(with_completion), 0.05 * linear_faces);
  }
}

TEST(ModalDerivatives, BadRequestsNameThePartFile) {
  const std::string bad = test::ThrownMessage(
      [] { ReducePart(ParsePart(Leaf(", modal_derivatives: {pairs: [[3, 99]]}"), "leaf.yaml"), nullptr); });
  EXPECT_NE(bad.find("leaf.yaml:7"), std::string::npos) << bad;
  EXPECT_NE(bad.find("[3, 99]"), std::string::npos) << bad;
}

}  // namespace
}  // namespace femb
