// What femb-inspect computes from a superelement file: free-free frequencies of the reduced
// model and the consistency checks. Dense linear algebra on the (small) reduced matrices.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "formats/superelement.h"

namespace femb {

struct Check {
  std::string name;
  bool ok = false;
  std::string detail;  ///< the measured figure behind the verdict
};

struct SuperelementAnalysis {
  Eigen::VectorXd free_free_frequencies_hz;    ///< all eigenvalues of (K, M), signed, ascending
  Eigen::Matrix<double, 6, 6> rigid_mass_frame;  ///< about the floating frame origin
  int rigid_body_mode_count = 0;
  std::vector<Check> checks;  ///< K_symmetric, M_symmetric, M_positive_definite, rigid_body_modes, floating_frame
  bool all_ok() const;
};

/// Thresholds: symmetry max|A - A^T| <= 1e-10 max|A|; rigid-body modes: |lambda| <= 1e-8 max|lambda|
/// counted, exactly 6 required, and ||K Phi_rig0|| <= 1e-8 ||K|| ||Phi_rig0||; floating frame:
/// max|Phi_CB Phi_rig0 - 1| <= 1e-8.
SuperelementAnalysis AnalyzeSuperelement(const Superelement& se);

}  // namespace femb
