// Axial spring-damper between two nodes (or a node and a fixed point): with d = x_b - x_a,
// l = |d|, e = d / l, ldot = e . (v_b - v_a), the tension N = k (l - l0) + c ldot pulls the ends
// together: f_a = N e, f_b = -N e. Potential k (l - l0)^2 / 2.
#pragma once

#include <Eigen/Core>

namespace femb {

struct SpringDamper {
  int node_a = -1;
  int node_b = -1;  ///< -1: the fixed point `ground`
  Eigen::Vector3d ground = Eigen::Vector3d::Zero();
  double stiffness = 0.0;    ///< k [force/length]
  double damping = 0.0;      ///< c [force time/length]
  double free_length = 0.0;  ///< l0 [length]
};

struct SpringDamperForces {
  Eigen::Matrix<double, 6, 1> f;  ///< forces on (a, b), translational components
  Eigen::Matrix<double, 6, 6> K;  ///< -d f / d (x_a, x_b)
  Eigen::Matrix<double, 6, 6> C;  ///< -d f / d (v_a, v_b)
  double energy = 0.0;
};

SpringDamperForces EvaluateSpringDamper(const SpringDamper& s, const Eigen::Vector3d& xa, const Eigen::Vector3d& xb,
                                        const Eigen::Vector3d& va, const Eigen::Vector3d& vb);

}  // namespace femb
