// Linearized modes about a state: K_t x = omega^2 M_g x with the full tangent K_t (material and
// geometric stiffness K1+K2+K3+K4, follower-load stiffness) and the mass M_g = P^T M P of the
// state; velocity-dependent terms are not included (undamped, non-rotating linearization).
#pragma once

#include <Eigen/Core>
#include <string>

#include "solver/assembly/system.h"

namespace femb {

struct ModalResult {
  bool ok = false;
  std::string message;
  Eigen::VectorXd frequencies_hz;  ///< ascending, signed: sign(lambda) sqrt|lambda| / 2 pi (negative: unstable)
  Eigen::MatrixXd shapes;          ///< over the unknowns, M-normalized
};

/// `load_time` is the time or pseudo-time at which the loads (for the geometric and follower
/// stiffness) are evaluated. At most `count` modes (all when <= 0).
ModalResult LinearizedModes(const SystemModel& model, SystemState& state, double load_time, int count = 0);

}  // namespace femb
