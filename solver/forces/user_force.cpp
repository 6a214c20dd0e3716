#include "solver/forces/user_force.h"

#include <algorithm>

#include "solver/assembly/system.h"
#include "solver/rotation.h"

namespace femb {

namespace {

// Forward differences of value(motion) in the motion's x, theta (R -> exp(theta~) R), v and w,
// with value0 = value(m), into columns first..first+5 of dq (x, theta) and dv (v, w): steps of
// 1e-7 of `length` in x, 1e-7 rad in theta, and 1e-7 of max(|v|, length / 1 s) and max(|w|,
// 1 rad/s) in the rates.
template <typename Vector, typename Matrix, typename Value>
void DifferenceMotion(const UserForceMotion& m, double length, const Vector& value0, const Value& value, int first,
                      Matrix& dq, Matrix& dv) {
  constexpr double kStep = 1e-7;
  const double hx = kStep * length, hv = kStep * std::max(m.v.norm(), length), hw = kStep * std::max(m.w.norm(), 1.0);
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d u = Eigen::Vector3d::Unit(i);
    UserForceMotion p = m;
    p.x += hx * u;
    dq.col(first + i) = (value(p) - value0) / hx;
    p = m;
    p.R = ExpSO3(kStep * u) * m.R;
    dq.col(first + 3 + i) = (value(p) - value0) / kStep;
    p = m;
    p.v += hv * u;
    dv.col(first + i) = (value(p) - value0) / hv;
    p = m;
    p.w += hw * u;
    dv.col(first + 3 + i) = (value(p) - value0) / hw;
  }
}

}  // namespace

void DifferenceUserForce(const UserNodeForce& force, double t, const Eigen::Vector3d& x, const Eigen::Matrix3d& R,
                         const Eigen::Vector3d& v, const Eigen::Vector3d& w, const UserNodeForce::Vector6& f,
                         double length, UserNodeForce::Matrix6& K, UserNodeForce::Matrix6& C) {
  const auto value = [&](const UserForceMotion& p) {
    UserNodeForce::Vector6 g;
    force.evaluate(t, p.x, p.R, p.v, p.w, g, nullptr, nullptr);
    return g;
  };
  DifferenceMotion(UserForceMotion{x, v, w, R}, length, f, value, 0, K, C);
}

namespace {

using Vector12 = Eigen::Matrix<double, 12, 1>;
using Matrix12 = Eigen::Matrix<double, 12, 12>;

// A force between two nodes: on (node, other), the force and its reaction (UserNodeForce::other).
// With dq and dv not null, also the pair's derivatives when the user function gives f's (returns
// whether it did): the reaction's, -dF and -dM - (x - x_other) x dF - (dx - dx_other) x F.
bool PairForces(const UserNodeForce& force, double t, const UserForceMotion (&m)[2], Vector12& g,
                Matrix12* dq = nullptr, Matrix12* dv = nullptr) {
  UserNodeForce::Vector6 f;
  UserNodeForce::Matrix6x12 K, C;
  const bool given = force.evaluate_pair(t, m[0], m[1], f, dq ? &K : nullptr, dv ? &C : nullptr);
  const Eigen::Vector3d arm = m[0].x - m[1].x;
  g.head<6>() = f;
  g.segment<3>(6) = -f.head<3>();
  g.tail<3>() = -f.tail<3>() - arm.cross(f.head<3>());
  if (!given) return false;
  const auto reaction = [&](const UserNodeForce::Matrix6x12& D, Matrix12& out) {
    out.topRows<6>() = D;
    out.middleRows<3>(6) = -D.topRows<3>();
    out.bottomRows<3>() = -D.bottomRows<3>() - Skew(arm) * D.topRows<3>();
  };
  if (dq) {
    reaction(K, *dq);
    const Eigen::Matrix3d F = Skew(Eigen::Vector3d(f.head<3>()));  // (dx_other - dx) x F = F~ (dx - dx_other)
    dq->block<3, 3>(9, 0) += F;
    dq->block<3, 3>(9, 6) -= F;
  }
  if (dv) reaction(C, *dv);
  return true;
}

// The pair's forces into the residual (the virtual work through both nodes' Jacobians), their
// derivatives into K and C: from the user function's (PairForces), or else by forward
// differences (DifferenceMotion).
void AddPairForce(const UserNodeForce& force, const SystemState& state, const Eigen::VectorXd& W, double t,
                  double length, Eigen::VectorXd* residual, Triplets* K, Triplets* C, NodeForces* node_forces) {
  const int nodes[2] = {force.node, force.other};
  UserForceMotion m[2];
  for (int e = 0; e < 2; ++e) {
    const Eigen::Matrix<double, 6, 1> motion = NodeMotion(state, nodes[e], W);
    m[e] = {state.x[nodes[e]], motion.head<3>(), motion.tail<3>(), state.R[nodes[e]]};
  }
  const bool matrices = K || C;
  Vector12 g;
  Matrix12 dq = Matrix12::Zero(), dv = Matrix12::Zero();
  const bool given = PairForces(force, t, m, g, matrices ? &dq : nullptr, matrices ? &dv : nullptr);
  if (matrices && !given) {
    for (int e = 0; e < 2; ++e) {
      const auto value = [&](const UserForceMotion& p) {
        UserForceMotion q[2] = {m[0], m[1]};
        q[e] = p;
        Vector12 h;
        PairForces(force, t, q, h);
        return h;
      };
      DifferenceMotion(m[e], length, g, value, 6 * e, dq, dv);
    }
  }
  for (int e = 0; e < 2; ++e) {
    if (node_forces) node_forces->Add(nodes[e], g.segment<6>(6 * e));
    for (const auto& [ci, vi] : state.J[nodes[e]]) {
      if (residual) (*residual)[ci] += vi.dot(g.segment<6>(6 * e));
      for (int e2 = 0; e2 < 2; ++e2) {
        for (const auto& [cj, vj] : state.J[nodes[e2]]) {
          if (K) K->emplace_back(ci, cj, -vi.dot(dq.block<6, 6>(6 * e, 6 * e2) * vj));
          if (C) C->emplace_back(ci, cj, -vi.dot(dv.block<6, 6>(6 * e, 6 * e2) * vj));
        }
      }
    }
  }
}

// A modal force's Q, and its derivatives (given, or by forward differences of 1e-7 of the
// largest |q| or |qdot|, at least 1e-6) into the modal rows and columns of body b.
void AddModalForce(const UserModalForce& force, const DofMap& dofs, const SystemState& state, const Eigen::VectorXd& W,
                   double t, Eigen::VectorXd* residual, Triplets* K, Triplets* C) {
  const int b = force.body, first = dofs.mode_dof(b);
  const Eigen::VectorXd& q = state.eta[size_t(b)];
  const long n = q.size();
  const Eigen::VectorXd qdot = W.size() ? Eigen::VectorXd(W.segment(first, n)) : Eigen::VectorXd::Zero(n);
  Eigen::VectorXd Q, g;
  Eigen::MatrixXd dq(n, n), dv(n, n);
  const bool matrices = K || C;
  const bool given = force.evaluate(t, q, qdot, Q, matrices ? &dq : nullptr, matrices ? &dv : nullptr);
  if (matrices && !given) {
    constexpr double kStep = 1e-7;
    const double hq = kStep * std::max(q.cwiseAbs().maxCoeff(), 1e-6);
    const double hv = kStep * std::max(qdot.cwiseAbs().maxCoeff(), 1e-6);
    for (long i = 0; i < n; ++i) {
      Eigen::VectorXd p = q;
      p[i] += hq;
      force.evaluate(t, p, qdot, g, nullptr, nullptr);
      dq.col(i) = (g - Q) / hq;
      p = qdot;
      p[i] += hv;
      force.evaluate(t, q, p, g, nullptr, nullptr);
      dv.col(i) = (g - Q) / hv;
    }
  }
  if (residual) residual->segment(first, n) += Q;
  for (long i = 0; i < n; ++i) {
    for (long j = 0; j < n; ++j) {
      if (K) K->emplace_back(first + int(i), first + int(j), -dq(i, j));
      if (C) C->emplace_back(first + int(i), first + int(j), -dv(i, j));
    }
  }
}

}  // namespace

// Each force's node: its motion from the velocities W (zero at rest: W empty), its force into
// the residual by the node Jacobian (the virtual work of force and moment: J^T f), -K and -C into
// the matrices, as the spring-dampers' (AddSpringDampers).
void AddUserForces(const SystemModel& model, const SystemState& state, const Eigen::VectorXd& W, double t,
                   Eigen::VectorXd* residual, Triplets* K, Triplets* C, NodeForces* node_forces) {
  for (const UserModalForce& force : model.user_modal_forces)
    AddModalForce(force, model.dofs(), state, W, t, residual, K, C);
  if (model.user_forces.empty()) return;
  const double length = ModelSize(model);
  UserNodeForce::Vector6 f;
  UserNodeForce::Matrix6 dfdq, dfdv;
  for (const UserNodeForce& force : model.user_forces) {
    if (force.other >= 0) {
      AddPairForce(force, state, W, t, length, residual, K, C, node_forces);
      continue;
    }
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
