#include "formats/superelement_checks.h"

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <limits>

#include "formats/input_error.h"

namespace femb {
namespace {

std::string Sci(const char* fmt, double v) {
  char buffer[128];
  std::snprintf(buffer, sizeof buffer, fmt, v);
  return buffer;
}

// The first entry of A that is NaN or infinite, as "(row, col) = value"; empty when all are finite.
template <typename Derived>
std::string FirstNonFinite(const Eigen::DenseBase<Derived>& A) {
  if (A.allFinite()) return "";
  for (Eigen::Index j = 0; j < A.cols(); ++j)
    for (Eigen::Index i = 0; i < A.rows(); ++i)
      if (!std::isfinite(A(i, j))) {
        char buffer[96];
        std::snprintf(buffer, sizeof buffer, "entry (%ld, %ld) is %g", long(i), long(j), double(A(i, j)));
        return buffer;
      }
  return "";
}

Check Finite(const Superelement& se) {
  // Each dataset where it is (no copy: the stresses and shapes of a solid part are large).
  std::string name, bad;
  const auto check = [&](const std::string& dataset, const auto& A) {
    if (!bad.empty()) return;
    bad = FirstNonFinite(A);
    if (!bad.empty()) name = dataset;
  };
  check("/reduced/K", se.K);
  check("/reduced/M", se.M);
  check("/reduced/internal_frequencies_hz", se.internal_frequencies_hz);
  check("/floating_frame/Phi_CB", se.floating_frame.Phi_CB);
  check("/floating_frame/origin", se.floating_frame.origin);
  check("/floating_frame/orientation", se.floating_frame.orientation);
  check("/mass_properties/mass", Eigen::MatrixXd::Constant(1, 1, se.mass_properties.mass));
  check("/mass_properties/center_of_mass", se.mass_properties.center_of_mass);
  check("/mass_properties/inertia_com", se.mass_properties.inertia_com);
  Eigen::MatrixXd positions(se.interfaces.size(), 3), orientations(se.interfaces.size(), 9);
  for (size_t k = 0; k < se.interfaces.size(); ++k) {
    positions.row(Eigen::Index(k)) = se.interfaces[k].position.transpose();
    orientations.row(Eigen::Index(k)) =
        Eigen::Map<const Eigen::Matrix<double, 1, 9>>(se.interfaces[k].orientation.data());
  }
  check("/interfaces/positions", positions);
  check("/interfaces/orientations", orientations);
  if (se.floating_frame.cardona_weights.size() > 0)
    check("/floating_frame/cardona_weights", se.floating_frame.cardona_weights);
  if (se.polynomial) {
    check("/reduced/polynomial/A", se.polynomial->A);
    check("/reduced/polynomial/B", se.polynomial->B);
  }
  for (const Eigen::MatrixXd& K_sigma : se.inertia_stiffness) check("/reduced/geometric_stiffness/inertia", K_sigma);
  if (se.interface_constraint.rows() > 0) check("/reduced/interface_constraint", se.interface_constraint);
  for (const Eigen::MatrixXd& G : se.inertia_gamma) check("/reduced/inertia_invariants/Gamma", G);
  for (const Eigen::MatrixXd& X : se.inertia_xi) check("/reduced/inertia_invariants/Xi", X);
  if (se.visualization) {
    check("/visualization/nodes", se.visualization->nodes);
    check("/visualization/shapes", se.visualization->shapes);
  }
  if (se.stress) {
    check("/stress/modes", se.stress->modes);
    check("/stress/inertia_modes", se.stress->inertia_modes);
    check("/stress/gradients", se.stress->gradients);
    check("/stress/element_quadratic", se.stress->element_quadratic);
    check("/stress/section_forces", se.stress->section_forces);
  }
  if (!bad.empty()) return {"finite", false, name + " " + bad, name};
  return {"finite", true, "every number of the datasets is finite", ""};
}

Check Symmetric(const std::string& name, const std::string& dataset, const Eigen::MatrixXd& A) {
  const double scale = A.cwiseAbs().maxCoeff();
  const double asym = (A - A.transpose()).cwiseAbs().maxCoeff();
  const double rel = scale > 0 ? asym / scale : 0.0;
  return {name, rel <= 1e-10, Sci("max|A - A^T| / max|A| = %.3g", rel), dataset};
}

}  // namespace

bool SuperelementChecks::all_ok() const { return first_failure() == nullptr; }

const Check* SuperelementChecks::first_failure() const {
  for (const Check& c : checks)
    if (!c.ok) return &c;
  return nullptr;
}

namespace {

// One check for the 12 inertia load cases' geometric stiffness: the first that fails, else the
// last.
void CheckInertiaStiffnessSymmetric(const Superelement& se, std::vector<Check>& checks) {
  for (size_t k = 0; k < se.inertia_stiffness.size(); ++k) {
    const Check c =
        Symmetric("inertia_stiffness_symmetric", "/reduced/geometric_stiffness/inertia", se.inertia_stiffness[k]);
    if (!c.ok || k + 1 == se.inertia_stiffness.size()) {
      checks.push_back(c);
      break;
    }
  }
}

// The floating frame: Phi_CB Phi_rig0 = 1, and the elastic projector T0 = 1 - Phi_rig0 Phi_CB
// moderate. `Ms`: M's symmetric part (positive definite when m_pd).
Check FloatingFrameCheck(const Superelement& se, const Eigen::MatrixXd& Phi_rig0, const Eigen::MatrixXd& Ms,
                         bool m_pd) {
  const double k_norm = se.K.norm();
  const double frame_error =
      (se.floating_frame.Phi_CB * Phi_rig0 - Eigen::Matrix<double, 6, 6>::Identity()).cwiseAbs().maxCoeff();
  // The body's elastic force sees K through the projector T0 = 1 - Phi_rig0 Phi_CB (thesis
  // 3.18 at the undeformed state): K T0 = K - (K Phi_rig0) Phi_CB must equal K. A frame
  // definition with huge entries (a mutated Phi_CB column of an internal mode, which
  // Phi_CB Phi_rig0 does not see) amplifies the round-off of K Phi_rig0 into the force.
  const double amplified = k_norm > 0 ? ((se.K * Phi_rig0) * se.floating_frame.Phi_CB).norm() / k_norm : 0.0;
  // And T0 itself must be a moderate projector in the mass metric, ||L^T T0 L^-T||_2 (M = L L^T):
  // 1 for mean axes (M-orthogonal), the body's aspect ratio or so for an interface frame; a huge
  // entry of Phi_CB where K Phi_rig0 happens to be exactly zero (found by fuzzing) makes it
  // astronomic while the residual above stays 0.
  double projector_norm = 0.0;
  if (m_pd) {
    const Eigen::MatrixXd T0 =
        Eigen::MatrixXd::Identity(se.K.rows(), se.K.cols()) - Phi_rig0 * se.floating_frame.Phi_CB;
    const Eigen::LLT<Eigen::MatrixXd> llt(Ms);
    const Eigen::MatrixXd L = llt.matrixL();
    // Y = T0 L^-T from L Y^T = T0^T; then L^T Y.
    const Eigen::MatrixXd Yt = L.triangularView<Eigen::Lower>().solve(Eigen::MatrixXd(T0.transpose()));
    const Eigen::MatrixXd A = L.transpose() * Yt.transpose();
    projector_norm = A.allFinite() ? Eigen::JacobiSVD<Eigen::MatrixXd>(A).singularValues()[0]
                                   : std::numeric_limits<double>::infinity();
  }
  return {"floating_frame", frame_error <= 1e-8 && amplified <= 1e-8 && projector_norm <= 1e6,
          Sci("max|Phi_CB Phi_rig0 - 1| = %.3g", frame_error) +
              Sci(", ||K Phi_rig0 Phi_CB|| / ||K|| = %.3g", amplified) +
              Sci(", ||1 - Phi_rig0 Phi_CB||_M = %.3g", projector_norm) +
              " (the elastic projector's norm in the mass metric: 1 for mean axes, about the part's "
              "aspect ratio for a centre-of-mass or interface frame; fails above 1e6)",
          "/floating_frame/Phi_CB"};
}

// The interfaces' orientations are rotations.
Check OrientationCheck(const Superelement& se) {
  double orientation_error = 0.0;
  std::string worst;
  for (const InterfaceNode& node : se.interfaces) {
    const Eigen::Matrix3d& R = node.orientation;
    const double e = std::max((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(),
                              std::abs(R.determinant() - 1.0));
    if (e > orientation_error) orientation_error = e, worst = node.name;
  }
  return {"interface_orientations", orientation_error <= 1e-9,
          Sci("max|R^T R - 1|, |det R - 1| = %.3g", orientation_error) +
              (worst.empty() ? "" : " (interface '" + worst + "')"),
          "/interfaces/orientations"};
}

// The modal derivatives' pairs: as many as the derivatives, each of reduced coordinates.
Check DerivativePairsCheck(const Superelement& se) {
  const int n = se.n_reduced_dofs();
  std::string bad_pair;
  if (long(se.modal_derivative_pairs.size()) != se.n_modal_derivatives) {
    bad_pair = std::to_string(se.modal_derivative_pairs.size()) + " pairs for " +
               std::to_string(se.n_modal_derivatives) + " modal derivatives";
  }
  for (size_t k = 0; k < se.modal_derivative_pairs.size() && bad_pair.empty(); ++k) {
    const auto [i, j] = se.modal_derivative_pairs[k];
    if (i < 0 || j < 0 || i >= n || j >= n) {
      bad_pair = "pair " + std::to_string(k) + " (" + std::to_string(i) + ", " + std::to_string(j) +
                 ") is outside the " + std::to_string(n) + " reduced coordinates";
    }
  }
  return {"modal_derivative_pairs", bad_pair.empty(),
          bad_pair.empty() ? std::to_string(se.modal_derivative_pairs.size()) + " pairs in range" : bad_pair,
          "/reduced/modal_derivative_pairs"};
}

// Thesis 8.2 case 4: the constraint must leave the rigid motions free (C Phi_rig0 = 0 on the
// interface rows) and have independent rows.
Check InterfaceConstraintCheck(const Superelement& se, const Eigen::MatrixXd& Phi_rig0) {
  const Eigen::MatrixXd& C = se.interface_constraint;
  const bool shaped = C.cols() == se.n_interface_dofs() && C.rows() < C.cols();
  double rigid = 1.0, condition = 0.0;
  if (shaped) {
    const Eigen::MatrixXd CP = C * Phi_rig0.topRows(C.cols());
    rigid = CP.norm() / std::max(C.norm() * Phi_rig0.topRows(C.cols()).norm(), 1e-300);
    const Eigen::VectorXd sv = Eigen::JacobiSVD<Eigen::MatrixXd>(C).singularValues();
    condition = sv.size() && sv[0] > 0 ? sv[sv.size() - 1] / sv[0] : 0.0;
  }
  return {"interface_constraint", shaped && rigid <= 1e-8 && condition > 1e-8,
          std::to_string(C.rows()) + " rows" + Sci(", ||C Phi_rig0|| / (||C|| ||Phi_rig0||) = %.3g", rigid) +
              Sci(", smallest / largest singular value %.3g", condition),
          "/reduced/interface_constraint"};
}

// The stored mass against the reduced M's.
Check MassCheck(const Superelement& se, const Eigen::MatrixXd& Phi_rig0) {
  const double m_reduced = (Phi_rig0.col(0).transpose() * se.M * Phi_rig0.col(0))(0, 0);
  const double mass_error = std::abs(m_reduced - se.mass_properties.mass) / std::max(std::abs(m_reduced), 1e-300);
  return {"mass", mass_error <= 1e-6,
          Sci("stored mass %.9g", se.mass_properties.mass) + Sci(", from the reduced M %.9g", m_reduced),
          "/mass_properties/mass"};
}

// Rigid motions cause no stress: the modal stresses of Phi_rig0's columns vanish to the single
// precision they are stored in (a mutated or mismatched stress dataset shows here).
Check StressRigidBodyCheck(const Superelement& se, const Eigen::MatrixXd& Phi_rig0) {
  const Eigen::MatrixXd modes = se.stress->modes.cast<double>();
  const double scale = modes.cwiseAbs().maxCoeff() * Phi_rig0.cwiseAbs().maxCoeff();
  const double relative = scale > 0 ? (modes * Phi_rig0).cwiseAbs().maxCoeff() / scale : 0.0;
  return {"stress_rigid_body", relative <= 1e-4,
          Sci("max|sigma(Phi_rig0)| = %.3g of max|sigma_i| max|Phi_rig0|", relative), "/stress/modes"};
}

// The inertia invariants: the frame's rotation turns a rigid translation e_b into the
// translation e_a x e_b: Gamma_a Phi_rig0 e_b = M Phi_rig0 (e_a x e_b) (b = translations), and
// Xi_aa is symmetric.
Check InertiaInvariantsCheck(const Superelement& se, const Eigen::MatrixXd& Phi_rig0) {
  const int n = se.n_reduced_dofs();
  double error = 0.0, scale = se.M.norm() * Phi_rig0.norm();
  bool shapes_ok = se.inertia_gamma.size() == 3 && se.inertia_xi.size() == 6;
  for (const Eigen::MatrixXd& X : se.inertia_gamma) shapes_ok &= X.rows() == n && X.cols() == n;
  for (const Eigen::MatrixXd& X : se.inertia_xi) shapes_ok &= X.rows() == n && X.cols() == n;
  for (int i = 0; shapes_ok && i < 3; ++i) {
    for (int b = 0; b < 3; ++b) {
      const Eigen::Vector3d turned = Eigen::Vector3d::Unit(i).cross(Eigen::Vector3d::Unit(b));
      const Eigen::VectorXd expected = se.M * (Phi_rig0.leftCols<3>() * turned);
      error = std::max(error, (se.inertia_gamma[size_t(i)] * Phi_rig0.col(b) - expected).norm());
    }
    error = std::max(error, (se.inertia_xi[size_t(i)] - se.inertia_xi[size_t(i)].transpose()).norm());
  }
  const double relative = scale > 0 ? error / scale : error;
  return {"inertia_invariants", shapes_ok && relative <= 1e-8,
          shapes_ok ? Sci("||Gamma_a Phi_rig0 e_b - M Phi_rig0 (e_a x e_b)||, ||Xi_aa - Xi_aa^T|| = %.3g "
                          "of ||M|| ||Phi_rig0||",
                          relative)
                    : std::string("need 3 Gamma and 6 Xi blocks of the reduced size"),
          "/reduced/inertia_invariants"};
}

}  // namespace

SuperelementChecks CheckSuperelement(const Superelement& se) {
  SuperelementChecks a;
  a.checks.push_back(Finite(se));
  if (!a.checks.back().ok) return a;  // the other figures would be meaningless
  a.checks.push_back(Symmetric("K_symmetric", "/reduced/K", se.K));
  a.checks.push_back(Symmetric("M_symmetric", "/reduced/M", se.M));
  CheckInertiaStiffnessSymmetric(se, a.checks);
  const Eigen::MatrixXd Ms = 0.5 * (se.M + se.M.transpose());
  const Eigen::MatrixXd Ks = 0.5 * (se.K + se.K.transpose());

  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> m_eig(Ms, Eigen::EigenvaluesOnly);
  const double m_min = m_eig.eigenvalues().size() ? m_eig.eigenvalues()[0] : 0.0;
  const bool m_pd = Eigen::LLT<Eigen::MatrixXd>(Ms).info() == Eigen::Success && m_min > 0.0;
  a.checks.push_back({"M_positive_definite", m_pd, Sci("smallest eigenvalue of M %.6g", m_min), "/reduced/M"});

  const Eigen::MatrixXd Phi_rig0 = RigidBodyModes(se, se.floating_frame.origin);
  if (m_pd) {
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(Ks, Ms, Eigen::EigenvaluesOnly);
    a.lambda = eig.eigenvalues();
    const double lmax = a.lambda.size() ? a.lambda.cwiseAbs().maxCoeff() : 0.0;
    for (int k = 0; k < a.lambda.size(); ++k) a.rigid_body_mode_count += std::abs(a.lambda[k]) <= 1e-8 * lmax;
  }
  const double k_norm = se.K.norm(), phi_norm = Phi_rig0.norm();
  const double residual = (k_norm > 0 && phi_norm > 0) ? (se.K * Phi_rig0).norm() / (k_norm * phi_norm) : 0.0;
  a.checks.push_back({"rigid_body_modes", m_pd && a.rigid_body_mode_count == 6 && residual <= 1e-8,
                      (m_pd ? std::to_string(a.rigid_body_mode_count) : std::string("(M not positive definite:) ?")) +
                          " eigenvalues with |lambda| <= 1e-8 max|lambda| (need 6), " +
                          Sci("||K Phi_rig0|| / (||K|| ||Phi_rig0||) = %.3g", residual),
                      "/reduced/K"});
  a.checks.push_back(FloatingFrameCheck(se, Phi_rig0, Ms, m_pd));
  a.checks.push_back(OrientationCheck(se));
  a.checks.push_back(DerivativePairsCheck(se));
  if (se.interface_constraint.rows() > 0) a.checks.push_back(InterfaceConstraintCheck(se, Phi_rig0));
  a.checks.push_back(MassCheck(se, Phi_rig0));
  if (se.stress && se.stress->modes.rows() > 0 && se.stress->modes.cols() == se.n_reduced_dofs()) {
    a.checks.push_back(StressRigidBodyCheck(se, Phi_rig0));
  }
  if (!se.inertia_gamma.empty()) a.checks.push_back(InertiaInvariantsCheck(se, Phi_rig0));
  return a;
}

void RequireValidSuperelement(const Superelement& se, const std::string& path) {
  const SuperelementChecks a = CheckSuperelement(se);
  if (const Check* c = a.first_failure()) {
    throw InputError(path + ": " + (c->dataset.empty() ? std::string("") : c->dataset + ": ") + "check " + c->name +
                     " failed: " + c->detail + " (femb-inspect --check lists every check; re-run femb-reduce)");
  }
}

}  // namespace femb
