#include "solver/forces/user_force.h"

#include <algorithm>

#include "solver/assembly/system.h"
#include "solver/rotation.h"

namespace femb {

void DifferenceUserForce(const UserNodeForce& force, double t, const Eigen::Vector3d& x, const Eigen::Matrix3d& R,
                         const Eigen::Vector3d& v, const Eigen::Vector3d& w, const UserNodeForce::Vector6& f,
                         double length, UserNodeForce::Matrix6& K, UserNodeForce::Matrix6& C) {
  constexpr double kStep = 1e-7;
  UserNodeForce::Vector6 g;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d e = Eigen::Vector3d::Unit(i);
    const double hx = kStep * length, hv = kStep * std::max(v.norm(), length), hw = kStep * std::max(w.norm(), 1.0);
    force.evaluate(t, x + hx * e, R, v, w, g, nullptr, nullptr);
    K.col(i) = (g - f) / hx;
    force.evaluate(t, x, ExpSO3(kStep * e) * R, v, w, g, nullptr, nullptr);
    K.col(3 + i) = (g - f) / kStep;
    force.evaluate(t, x, R, v + hv * e, w, g, nullptr, nullptr);
    C.col(i) = (g - f) / hv;
    force.evaluate(t, x, R, v, w + hw * e, g, nullptr, nullptr);
    C.col(3 + i) = (g - f) / hw;
  }
}

// Each force's node: its motion from the velocities W (zero at rest: W empty), its force into
// the residual by the node Jacobian (the virtual work of force and moment: J^T f), -K and -C into
// the matrices, as the spring-dampers' (AddSpringDampers).
void AddUserForces(const SystemModel& model, const SystemState& state, const Eigen::VectorXd& W, double t,
                   Eigen::VectorXd* residual, Triplets* K, Triplets* C, NodeForces* node_forces) {
  if (model.user_forces.empty()) return;
  double length = BoundingDiagonal(model.node_x0);
  if (!(length > 0)) length = 1.0;
  UserNodeForce::Vector6 f;
  UserNodeForce::Matrix6 dfdq, dfdv;
  for (const UserNodeForce& force : model.user_forces) {
    const int k = force.node;
    const Eigen::Matrix<double, 6, 1> motion = NodeMotion(state, k, W);
    const Eigen::Vector3d v = motion.head<3>(), w = motion.tail<3>();
    const bool matrices = K || C;
    const bool given =
        force.evaluate(t, state.x[k], state.R[k], v, w, f, matrices ? &dfdq : nullptr, matrices ? &dfdv : nullptr);
    if (matrices && !given) DifferenceUserForce(force, t, state.x[k], state.R[k], v, w, f, length, dfdq, dfdv);
    if (node_forces) node_forces->Add(k, f);
    const NodeJacobian& J = state.J[k];
    for (const auto& [ci, vi] : J) {
      if (residual) (*residual)[ci] += vi.dot(f);
      for (const auto& [cj, vj] : J) {
        if (K) K->emplace_back(ci, cj, -vi.dot(dfdq * vj));
        if (C) C->emplace_back(ci, cj, -vi.dot(dfdv * vj));
      }
    }
  }
}

}  // namespace femb
