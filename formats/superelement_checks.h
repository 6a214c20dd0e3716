// The consistency checks of a superelement: what femb-reduce guarantees when it writes a file,
// what femb-solve requires when it loads one and what femb-inspect --check reports. Dense linear
// algebra on the (small) reduced matrices; no file access.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "formats/superelement.h"

namespace femb {

struct Check {
  std::string name;
  bool ok = false;
  std::string detail;   ///< the measured figure behind the verdict
  std::string dataset;  ///< the dataset of the file the check is about (e.g. "/reduced/M")
};

struct SuperelementChecks {
  std::vector<Check> checks;
  /// Eigenvalues omega^2 of (K, M), ascending; empty when M is not positive definite or a
  /// dataset is not finite.
  Eigen::VectorXd lambda;
  int rigid_body_mode_count = 0;
  bool all_ok() const;
  /// The first failed check, or nullptr.
  const Check* first_failure() const;
};

/// Runs every check, in this order (only the first when a dataset is not finite: the other
/// figures would be meaningless):
///   finite                  every number of the file's datasets is finite (names the first
///                           dataset and entry that is not)
///   K_symmetric, M_symmetric  max|A - A^T| <= 1e-10 max|A|
///   M_positive_definite     Cholesky of M succeeds and its smallest eigenvalue is > 0
///   rigid_body_modes        exactly 6 eigenvalues of (K, M) with |lambda| <= 1e-8 max|lambda|,
///                           and ||K Phi_rig0|| <= 1e-8 ||K|| ||Phi_rig0|| (thesis 3.20)
///   floating_frame          max|Phi_CB Phi_rig0 - 1| <= 1e-8 (thesis 3.7, 3.20)
///   interface_orientations  every orientation orthonormal with determinant +1 (to 1e-9)
///   modal_derivative_pairs  every pair names reduced coordinates of the file
///   interface_constraint    (only with one) C Phi_rig0 = 0 on the interface rows (1e-8) and
///                           independent rows (singular values within 1e8)
///   mass                    the stored mass equals the one of the reduced M to 1e-6
SuperelementChecks CheckSuperelement(const Superelement& se);

/// femb-solve's gate: throws InputError "PATH: DATASET: check NAME failed: DETAIL" on the first
/// failed check.
void RequireValidSuperelement(const Superelement& se, const std::string& path);

}  // namespace femb
