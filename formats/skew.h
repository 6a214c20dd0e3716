// The cross-product matrix, shared by the reducer and the solver.
#pragma once

#include <Eigen/Core>

namespace femb {

/// a~ such that a~ b = a x b (any scalar type: the solver differentiates through it).
template <typename S>
Eigen::Matrix<S, 3, 3> Skew(const Eigen::Matrix<S, 3, 1>& a) {
  Eigen::Matrix<S, 3, 3> m;
  m << S(0), -a.z(), a.y(), a.z(), S(0), -a.x(), -a.y(), a.x(), S(0);
  return m;
}

}  // namespace femb
