// What femb-inspect computes from a superelement file: free-free frequencies of the reduced
// model and the consistency checks (formats/superelement_checks.h, shared with femb-solve's gate
// and femb-reduce's last step).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "formats/superelement.h"
#include "formats/superelement_checks.h"

namespace femb {

struct SuperelementAnalysis {
  Eigen::VectorXd free_free_frequencies_hz;      ///< all eigenvalues of (K, M), signed, ascending
  Eigen::Matrix<double, 6, 6> rigid_mass_frame;  ///< about the floating frame origin
  int rigid_body_mode_count = 0;
  std::vector<Check> checks;  ///< CheckSuperelement's, in its order
  bool all_ok() const;
};

/// The checks of CheckSuperelement, the free-free frequencies from its eigenvalues and the
/// rigid-body mass matrix about the floating frame origin (when every dataset is finite).
SuperelementAnalysis AnalyzeSuperelement(const Superelement& se);

}  // namespace femb
