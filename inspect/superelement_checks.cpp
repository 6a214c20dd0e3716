#include "inspect/superelement_checks.h"

#include <Eigen/Dense>
#include <cstdio>

namespace femb {
namespace {

std::string Sci(const char* fmt, double v) {
  char buffer[96];
  std::snprintf(buffer, sizeof buffer, fmt, v);
  return buffer;
}

Check Symmetric(const std::string& name, const Eigen::MatrixXd& A) {
  const double scale = A.cwiseAbs().maxCoeff();
  const double asym = (A - A.transpose()).cwiseAbs().maxCoeff();
  const double rel = scale > 0 ? asym / scale : 0.0;
  return {name, rel <= 1e-10, Sci("max|A - A^T| / max|A| = %.3g", rel)};
}

}  // namespace

bool SuperelementAnalysis::all_ok() const {
  for (const Check& c : checks) {
    if (!c.ok) return false;
  }
  return true;
}

SuperelementAnalysis AnalyzeSuperelement(const Superelement& se) {
  SuperelementAnalysis a;
  a.checks.push_back(Symmetric("K_symmetric", se.K));
  a.checks.push_back(Symmetric("M_symmetric", se.M));
  const Eigen::MatrixXd Ms = 0.5 * (se.M + se.M.transpose());
  const Eigen::MatrixXd Ks = 0.5 * (se.K + se.K.transpose());

  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> m_eig(Ms, Eigen::EigenvaluesOnly);
  const double m_min = m_eig.eigenvalues().size() ? m_eig.eigenvalues()[0] : 0.0;
  const bool m_pd = Eigen::LLT<Eigen::MatrixXd>(Ms).info() == Eigen::Success && m_min > 0.0;
  a.checks.push_back({"M_positive_definite", m_pd, Sci("smallest eigenvalue of M %.6g", m_min)});

  const Eigen::MatrixXd Phi_rig0 = RigidBodyModes(se, se.floating_frame.origin);
  a.rigid_mass_frame = RigidBodyMassMatrix(se, se.floating_frame.origin);
  if (m_pd) {
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(Ks, Ms, Eigen::EigenvaluesOnly);
    const Eigen::VectorXd lambda = eig.eigenvalues();
    a.free_free_frequencies_hz.resize(lambda.size());
    for (int k = 0; k < lambda.size(); ++k) a.free_free_frequencies_hz[k] = FrequencyHz(lambda[k]);
    const double lmax = lambda.cwiseAbs().maxCoeff();
    for (int k = 0; k < lambda.size(); ++k) a.rigid_body_mode_count += std::abs(lambda[k]) <= 1e-8 * lmax;
  }
  const double k_norm = se.K.norm(), phi_norm = Phi_rig0.norm();
  const double residual = (k_norm > 0 && phi_norm > 0) ? (se.K * Phi_rig0).norm() / (k_norm * phi_norm) : 0.0;
  a.checks.push_back({"rigid_body_modes", a.rigid_body_mode_count == 6 && residual <= 1e-8,
                      std::to_string(a.rigid_body_mode_count) + " eigenvalues with |lambda| <= 1e-8 max|lambda| (need 6), " +
                          Sci("||K Phi_rig0|| / (||K|| ||Phi_rig0||) = %.3g", residual)});
  const double frame_error =
      (se.floating_frame.Phi_CB * Phi_rig0 - Eigen::Matrix<double, 6, 6>::Identity()).cwiseAbs().maxCoeff();
  a.checks.push_back({"floating_frame", frame_error <= 1e-8,
                      Sci("max|Phi_CB Phi_rig0 - 1| = %.3g", frame_error)});
  return a;
}

}  // namespace femb
