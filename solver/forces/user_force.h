// A force the user writes as a function (the Python module's Scene.add_force): on one node, in
// world axes, of time and the node's motion. It enters the residual, the iteration matrix and
// the node forces (reactions) as the built-in loads do, and the external work (the energy
// balance): in statics, at rest, with the load factor as its time.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <stdexcept>
#include <string>

namespace femb {

/// What a user function did wrong (raised, NaN, a wrong shape), with its name and time: the run
/// stops there as on a numerical failure, with the results up to it kept.
class UserForceError : public std::runtime_error {
 public:
  explicit UserForceError(const std::string& message) : std::runtime_error(message) {}
};

/// A node's motion as a user function sees it (world axes).
struct UserForceMotion {
  Eigen::Vector3d x, v, w;
  Eigen::Matrix3d R;
};

struct UserNodeForce {
  using Vector6 = Eigen::Matrix<double, 6, 1>;
  using Matrix6 = Eigen::Matrix<double, 6, 6>;
  int node = -1;
  /// A force between two nodes: the node the force's reaction acts on, or -1 (a force on `node`
  /// alone). Then `evaluate_pair` gives the force on `node`, and `other` takes its opposite and
  /// the opposite moment about itself, -M - (x_node - x_other) x F: the pair's forces balance, its
  /// momentum is kept.
  int other = -1;
  std::string name;  ///< for messages ("force 'bump_stop' on node 'tip'")
  using Matrix6x12 = Eigen::Matrix<double, 6, 12>;
  /// f = (force, moment about `node`) on `node` from the motions of `node` and `other`. With K
  /// and C not null it may also give K = d f / d (x, theta, x_other, theta_other) and
  /// C = d f / d (v, w, v_other, w_other), and returns whether it did; femb differences f where
  /// it did not (the reaction's derivatives follow from f's). Throws UserForceError.
  std::function<bool(double t, const UserForceMotion& node, const UserForceMotion& other, Vector6& f, Matrix6x12* K,
                     Matrix6x12* C)>
      evaluate_pair;
  /// f = (force, moment about the node) in world axes, at time t of the node's position x,
  /// rotation R (node axes in world axes), velocity v and angular velocity w (world axes). With K
  /// and C not null it may also give K = d f / d (x, theta) and C = d f / d (v, w), theta the
  /// spatial rotation increment (R -> exp(theta~) R), and returns whether it did; femb
  /// differences f where it did not. Throws UserForceError.
  std::function<bool(double t, const Eigen::Vector3d& x, const Eigen::Matrix3d& R, const Eigen::Vector3d& v,
                     const Eigen::Vector3d& w, Vector6& f, Matrix6* K, Matrix6* C)>
      evaluate;
};

/// A generalized force the user writes on a flexible body's modal coordinates q (the internal
/// coordinates of its reduced basis, as in results.h5's modal_coordinates): Q (one per
/// coordinate) of time and q, qdot, entering the residual as applied forces (virtual work Q . dq).
struct UserModalForce {
  int body = -1;
  std::string name;
  /// Q at (t, q, qdot); with K and C not null it may also give K = dQ/dq and C = dQ/dqdot (n x n)
  /// and returns whether it did (else femb differences Q). Throws UserForceError.
  std::function<bool(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& qdot, Eigen::VectorXd& Q,
                     Eigen::MatrixXd* K, Eigen::MatrixXd* C)>
      evaluate;
};

/// K = d f / d (x, theta) and C = d f / d (v, w) of `force` at (t, x, R, v, w), f its value
/// there, by forward differences (12 more evaluations): steps of 1e-7 of `length` in x, 1e-7
/// rad in theta, and 1e-7 of max(|v|, length / 1 s) and max(|w|, 1 rad/s) in the rates.
void DifferenceUserForce(const UserNodeForce& force, double t, const Eigen::Vector3d& x, const Eigen::Matrix3d& R,
                         const Eigen::Vector3d& v, const Eigen::Vector3d& w, const UserNodeForce::Vector6& f,
                         double length, UserNodeForce::Matrix6& K, UserNodeForce::Matrix6& C);

}  // namespace femb
