#include "formats/superelement.h"

#include <algorithm>
#include <cstdio>

namespace femb {

std::string DynamicsSummary(const Superelement& se) {
  if (se.n_reduced_dofs() <= 6) return "rigid (one interface, no modes): the rigid body's exact inertia";
  std::string s = se.inertia_gamma.empty()
                      ? "corotational inertia only (no inertia invariants: an older femb-reduce wrote the file; a "
                        "spinning part's centrifugal load on its deformation is then a fifth too high)"
                      : "exact inertia (inertia invariants)";
  if (se.polynomial && se.polynomial->cubic()) {
    s += "; large deformation inside (modal derivatives, cubic internal force)";
    if (!se.inertia_stiffness.empty()) s += " and the inertia loads' geometric stiffening";
  } else if (!se.inertia_stiffness.empty()) {
    s += "; geometric stiffening of the inertia loads and the basis's own stress";
  } else {
    s += "; no geometric stiffening: linear inside (a rotating or highly loaded part misses its stress stiffening)";
  }
  return s;
}

std::string ReducedCoordinateLabel(const Superelement& se, int i) {
  static const char* kComponents[6] = {"u_x", "u_y", "u_z", "theta_x", "theta_y", "theta_z"};
  if (i < 0 || i >= se.n_interface_dofs() + se.n_internal_modes() + int(se.n_modal_derivatives)) {
    return "coordinate " + std::to_string(i) + " (out of range)";  // a corrupt pair of a file
  }
  if (i < se.n_interface_dofs()) {
    return se.interfaces[i / 6].name + "." + kComponents[i % 6];
  }
  int mode = i - se.n_interface_dofs();
  if (mode >= se.n_internal_modes()) {
    const int d = mode - se.n_internal_modes();
    std::string label = "derivative " + std::to_string(d + 1);
    if (d < int(se.modal_derivative_pairs.size())) {
      const auto [a, b] = se.modal_derivative_pairs[size_t(d)];
      const auto base = [&](int k) {
        return k >= 0 && k < se.n_interface_dofs() + se.n_internal_modes() ? ReducedCoordinateLabel(se, k)
                                                                           : std::to_string(k);
      };
      std::string la = base(a), lb = base(b);
      for (std::string* l : {&la, &lb})
        if (l->rfind("mode ", 0) == 0) *l = l->substr(0, l->find(" ("));
      label += " (" + la + " x " + lb + ")";
    }
    return label;
  }
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "mode %d (%.6g Hz)", mode + 1, se.internal_frequencies_hz[mode]);
  return buffer;
}

Eigen::Matrix<double, 6, 6> NodeRigidBodyModes(const Eigen::Vector3d& x) {
  // thesis (3.12): [1, -x~; 0, 1] with x the node position relative to the frame origin.
  Eigen::Matrix<double, 6, 6> block = Eigen::Matrix<double, 6, 6>::Identity();
  block(0, 4) = x.z();
  block(0, 5) = -x.y();
  block(1, 3) = -x.z();
  block(1, 5) = x.x();
  block(2, 3) = x.y();
  block(2, 4) = -x.x();
  return block;
}

Eigen::MatrixXd RigidBodyModes(const Superelement& se, const Eigen::Vector3d& origin) {
  Eigen::MatrixXd Phi_rig0 = Eigen::MatrixXd::Zero(se.n_reduced_dofs(), 6);
  for (int k = 0; k < se.n_interface_nodes(); ++k) {
    Phi_rig0.block(6 * k, 0, 6, 6) = NodeRigidBodyModes(se.interfaces[k].position - origin);
  }
  return Phi_rig0;
}

}  // namespace femb

namespace femb {

Eigen::Matrix<double, 6, 6> RigidBodyMassMatrix(const Superelement& se, const Eigen::Vector3d& origin) {
  const Eigen::MatrixXd Phi_rig0 = RigidBodyModes(se, origin);
  Eigen::Matrix<double, 6, 6> M_rig = Phi_rig0.transpose() * se.M * Phi_rig0;
  return 0.5 * (M_rig + M_rig.transpose());
}

MassProperties ComputeMassProperties(const Superelement& se) {
  const Eigen::Matrix<double, 6, 6> M0 = RigidBodyMassMatrix(se, Eigen::Vector3d::Zero());
  MassProperties p;
  p.mass = M0.block<3, 3>(0, 0).trace() / 3.0;
  // Lower-left block is m c~ (skew): read c from its antisymmetric part.
  const Eigen::Matrix3d mc = M0.block<3, 3>(3, 0);
  const Eigen::Vector3d c =
      Eigen::Vector3d(mc(2, 1) - mc(1, 2), mc(0, 2) - mc(2, 0), mc(1, 0) - mc(0, 1)) / (2.0 * p.mass);
  p.center_of_mass = c;
  // Parallel axis theorem: J_0 = J_c + m (|c|^2 1 - c c^T).
  p.inertia_com = M0.block<3, 3>(3, 3) - p.mass * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
  return p;
}

}  // namespace femb

#include <Eigen/Eigenvalues>
#include <cmath>
namespace femb {
double FrequencyHz(double lambda) { return std::copysign(std::sqrt(std::abs(lambda)), lambda) / (2.0 * M_PI); }

double VonMises(const Eigen::Matrix<double, 6, 1>& s) {
  const double a = s[0] - s[1], b = s[1] - s[2], c = s[2] - s[0];
  return std::sqrt(0.5 * (a * a + b * b + c * c) + 3.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]));
}

namespace {

// The closed form of a symmetric 3 x 3 eigenproblem (Smith 1961): with the mean stress m and the
// deviator B = S - m 1 scaled by p = sqrt(|B|_F^2 / 6), the roots are m + 2 p cos(phi + 2 pi k /
// 3), cos(3 phi) = x = det(B / p) / 2, phi in [0, pi / 3]; p = 0 for a hydrostatic state. Near a
// double root (x = +-1) the roots are right to about 1e-8 of p: the root's own condition there.
struct PrincipalInvariants {
  double m = 0.0, p = 0.0, x = 0.0;
};
PrincipalInvariants PrincipalInvariantsOf(const Eigen::Matrix<double, 6, 1>& s) {
  PrincipalInvariants a;
  a.m = (s[0] + s[1] + s[2]) / 3.0;
  const double b0 = s[0] - a.m, b1 = s[1] - a.m, b2 = s[2] - a.m;
  const double p2 = (b0 * b0 + b1 * b1 + b2 * b2 + 2.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5])) / 6.0;
  if (p2 <= 1e-300) return a;
  a.p = std::sqrt(p2);
  // det(B) / p^3 / 2 for B = [b0 s5 s4; s5 b1 s3; s4 s3 b2].
  const double det = b0 * (b1 * b2 - s[3] * s[3]) - s[5] * (s[5] * b2 - s[3] * s[4]) + s[4] * (s[5] * s[3] - b1 * s[4]);
  a.x = std::clamp(det / (2.0 * p2 * a.p), -1.0, 1.0);
  return a;
}

}  // namespace

Eigen::Vector3d PrincipalStresses(const Eigen::Matrix<double, 6, 1>& s) {
  // At a tenth of the iterative solver's cost (the animation's stress fields took a third of a
  // solid cantilever's run).
  const PrincipalInvariants a = PrincipalInvariantsOf(s);
  if (a.p == 0.0) return Eigen::Vector3d::Constant(a.m);
  const double phi = std::acos(a.x) / 3.0;
  const double l1 = a.m + 2.0 * a.p * std::cos(phi), l3 = a.m + 2.0 * a.p * std::cos(phi + 2.0 * M_PI / 3.0);
  return Eigen::Vector3d(l1, 3.0 * a.m - l1 - l3, l3);
}

Eigen::Vector2d ExtremePrincipalStresses(const Eigen::Matrix<double, 6, 1>& s) {
  // PrincipalStresses' largest and smallest roots, m + 2 p c and m - p (c + sqrt(3) sqrt(1 -
  // c^2)) with c = cos(phi), the largest root of f(c) = 4 c^3 - 3 c - x (c in [1/2, 1], where f
  // increases and is convex), by Newton's method instead of acos and cos: a third of the cost of
  // the animation's stress fields went to the trigonometry. From c0 = 1/2 + sqrt((1 + x) / 8),
  // exact at x = 1 and x = -1; near x = -1 (the largest two principal stresses equal) the root
  // is 1/2 + sqrt((1 + x) / 6) + O(1 + x), which the start meets to 13%, and four steps take that
  // to 1%, 5e-5, 1e-9 and the round-off.
  const PrincipalInvariants a = PrincipalInvariantsOf(s);
  if (a.p == 0.0) return Eigen::Vector2d::Constant(a.m);
  double c = 0.5 + std::sqrt(0.125 * (1.0 + a.x));
  for (int k = 0; k < 4; ++k) {
    const double slope = 12.0 * c * c - 3.0;
    if (!(slope > 0.0)) break;  // c = 1/2 exactly: x = -1, the root
    c -= (4.0 * c * c * c - 3.0 * c - a.x) / slope;
  }
  c = std::clamp(c, 0.5, 1.0);
  return Eigen::Vector2d(a.m + 2.0 * a.p * c, a.m - a.p * (c + std::sqrt(3.0 * (1.0 - c * c))));
}

namespace {

// D E_quad of St. Venant-Kirchhoff at point p: E_quad = H^T H / 2 with H = sum_i q_i H_i
// (Voigt xx, yy, zz, yz, xz, xy; engineering shear 2 E_ij).
Eigen::Matrix<double, 6, 1> QuadraticStress(const ModalStress& modal, long p, const Eigen::VectorXd& q) {
  if (modal.element_quadratic.size() > 0) {
    // Beams: E q^T Q_e q / 2 along the element axis e1: (e1 e1^T) in Voigt order.
    const int e = modal.point_element[p];
    double c = 0;
    long k = 0;
    for (long i = 0; i < q.size(); ++i) {
      c += 0.5 * modal.element_quadratic(e, k++) * q[i] * q[i];
      for (long j = i + 1; j < q.size(); ++j) c += modal.element_quadratic(e, k++) * q[i] * q[j];
    }
    const Eigen::Vector3d e1 = modal.element_axes.row(e).head<3>().transpose();
    Eigen::Matrix<double, 6, 1> s;
    s << e1[0] * e1[0], e1[1] * e1[1], e1[2] * e1[2], e1[1] * e1[2], e1[0] * e1[2], e1[0] * e1[1];
    return modal.E * c * s;
  }
  const Eigen::Matrix<double, 9, 1> h = modal.gradients.middleRows(9 * p, 9).cast<double>() * q;
  const Eigen::Matrix3d H = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(h.data());
  const Eigen::Matrix3d Eq = 0.5 * H.transpose() * H;
  const double lambda = modal.E * modal.nu / ((1 + modal.nu) * (1 - 2 * modal.nu)), mu = modal.E / (2 * (1 + modal.nu));
  const double trace = Eq.trace();
  Eigen::Matrix<double, 6, 1> s;
  s << lambda * trace + 2 * mu * Eq(0, 0), lambda * trace + 2 * mu * Eq(1, 1), lambda * trace + 2 * mu * Eq(2, 2),
      2 * mu * Eq(1, 2), 2 * mu * Eq(0, 2), 2 * mu * Eq(0, 1);
  return s;
}

}  // namespace

Eigen::Matrix<double, 6, 1> PointStress(const ModalStress& modal, int p, const Eigen::VectorXd& q,
                                        const Eigen::VectorXd* inertia) {
  Eigen::Matrix<double, 6, 1> s = modal.modes.middleRows(6 * p, 6).cast<double>() * q;
  if (inertia && modal.inertia_modes.size() > 0)
    s += modal.inertia_modes.middleRows(6 * p, 6).cast<double>() * *inertia;
  if (modal.gradients.size() > 0 || modal.element_quadratic.size() > 0) s += QuadraticStress(modal, p, q);
  return s;
}

void NodeStresses(const ModalStress& modal, const Eigen::VectorXd& q, long n_nodes, Eigen::MatrixXd* stress,
                  Eigen::VectorXd* von_mises, const Eigen::VectorXd* inertia, Eigen::VectorXf* scratch) {
  stress->setZero(n_nodes, 6);
  von_mises->setConstant(n_nodes, -1.0);
  // The field in single precision, the precision of the modes themselves (a sum of n terms adds
  // sqrt(n) of their 6e-8 rounding): one pass over the stored modes without a copy, a tenth of
  // the cost of turning them to double precision first. The quadratic stress, von Mises and the
  // largest per node in double precision.
  const bool with_inertia = inertia && modal.inertia_modes.size() > 0;
  const bool quadratic = modal.gradients.size() > 0 || modal.element_quadratic.size() > 0;
  // (`scratch`: the field's storage kept by the caller from call to call; a field-sized
  // temporary per call cost page faults at every output step.)
  Eigen::VectorXf own;
  Eigen::VectorXf& all = scratch ? *scratch : own;
  all.noalias() = modal.modes * q.cast<float>();
  if (with_inertia) all.noalias() += modal.inertia_modes * inertia->cast<float>();
  for (int p = 0; p < modal.n_points(); ++p) {
    Eigen::Matrix<double, 6, 1> s = all.segment<6>(6 * p).cast<double>();
    if (quadratic) s += QuadraticStress(modal, p, q);
    const double v = VonMises(s);
    const int k = modal.node[p];
    if (v > (*von_mises)[k]) {
      (*von_mises)[k] = v;
      stress->row(k) = s.transpose();
    }
  }
  *von_mises = von_mises->cwiseMax(0.0);
}
}  // namespace femb
