// The derivatives of the node accelerations of the joint tree (NodeAccelerations) with respect
// to the coordinate velocities and the coordinates: the Coriolis, centripetal and configuration
// terms of chains with offsets in the dynamic iteration matrix. Declared in joint_tree.h.
#include <Eigen/Dense>
#include <algorithm>
#include <vector>

#include "solver/joints/joint_tree.h"

namespace femb {

void ConvectiveVelocityDerivative(const SystemModel& model, const DofMap& dofs, const SystemState& state,
                                  const Eigen::VectorXd& W, std::vector<NodeJacobian>& dc) {
  dc.resize(size_t(model.n_nodes()));
  for (NodeJacobian& d : dc) d.clear();  // storage kept
  for (int k : dofs.order()) {
    const int j = dofs.joint_of(k);
    if (j < 0) continue;
    const NodeJoint& joint = model.joints[size_t(j)];
    const int p = joint.parent;
    if (ConstantMaps(joint)) continue;  // no terms
    const ParentNode parent = ParentOf(state, p);
    const JointMaps maps = ComputeJointMaps(joint, parent.x, parent.R, state.x[k], state.z[k]);
    const JointVector zdot = W.segment(dofs.node_first(k), dofs.node_count(k));
    const Eigen::Vector3d rho = state.x[k] - parent.x, g = parent.R * joint.axis;
    const Eigen::Vector3d omega = NodeMotion(state, p, W).tail<3>();
    const double sdot = joint.s_index() >= 0 ? zdot[joint.s_index()] : 0.0;
    const double phidot = joint.phi_index() >= 0 ? zdot[joint.phi_index()] : 0.0;
    // c_c = A c_p + [w x (w x rho) + 2 sdot w x g; phidot w x g] (+ universal terms), w the
    // parent's angular velocity (ChildConvective): differentiated in W.
    NodeJacobian& d = dc[size_t(k)];
    auto add = [&d](int col, const Eigen::Matrix<double, 6, 1>& v) {
      for (auto& [c, u] : d) {
        if (c == col) {
          u += v;
          return;
        }
      }
      d.emplace_back(col, v);
    };
    if (p != kGround)
      for (const auto& [col, v] : dc[size_t(p)]) add(col, maps.A * v);
    Eigen::Vector3d g1 = Eigen::Vector3d::Zero(), g2 = Eigen::Vector3d::Zero();
    if (joint.type == JointType::kUniversal) g1 = maps.B.col(0).tail<3>(), g2 = maps.B.col(1).tail<3>();
    for (const auto& [col, v] : parent.J) {
      const Eigen::Vector3d r = v.tail<3>();  // d omega / dW_col
      if (r.squaredNorm() == 0) continue;
      Eigen::Matrix<double, 6, 1> e;
      e.head<3>() = r.cross(omega.cross(rho)) + omega.cross(r.cross(rho)) + 2 * sdot * r.cross(g);
      e.tail<3>() = phidot * r.cross(g);
      if (joint.type == JointType::kUniversal) e.tail<3>() += zdot[0] * r.cross(g1) + zdot[1] * r.cross(g2);
      if (e.squaredNorm() > 0) add(col, e);
    }
    const int first = dofs.node_first(k);
    Eigen::Matrix<double, 6, 1> e = Eigen::Matrix<double, 6, 1>::Zero();
    if (joint.s_index() >= 0) {
      e.head<3>() = 2 * omega.cross(g);
      if (e.squaredNorm() > 0) add(first + joint.s_index(), e);
    }
    if (joint.phi_index() >= 0) {
      e.setZero();
      e.tail<3>() = omega.cross(g);
      if (e.squaredNorm() > 0) add(first + joint.phi_index(), e);
    }
    if (joint.type == JointType::kUniversal) {
      e.setZero();
      e.tail<3>() = omega.cross(g1) + zdot[1] * g1.cross(g2);
      if (e.squaredNorm() > 0) add(first, e);
      e.tail<3>() = omega.cross(g2) + zdot[0] * g1.cross(g2);
      if (e.squaredNorm() > 0) add(first + 1, e);
    }
  }
}

void NodeAccelerationConfigurationDerivative(const SystemModel& model, const DofMap& dofs, const SystemState& state,
                                             const Eigen::VectorXd& W, const Eigen::VectorXd& Wdot,
                                             std::vector<NodeJacobian>& out, SystemScratch* scratch) {
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  const int n = model.n_nodes();
  // Down the tree, per node: velocity and acceleration, and per coordinate their derivatives.
  //   vel_c = A vel_p + B zdot,  acc_c = A acc_p + B zddot + [w x (w x rho) + 2 sdot w x g;
  //   phidot w x g] (+ universal terms; ChildConvective), w the parent's angular velocity;
  // a coordinate turns the parent (dpi_p, its column of J_p), moves the parent's velocity and
  // acceleration (their derivatives), and its own joint coordinates: d rho = dpi_p x rho + g ds,
  // d g = dpi_p x g (universal: d g2 = dpi_p x g2 + dphi1 g1 x g2), d(A v) = [v_w x d rho; 0].
  using Column = SystemScratch::RateColumn;
  SystemScratch own;
  SystemScratch& s = scratch ? *scratch : own;
  std::vector<std::vector<Column>>& d = s.rate_columns;
  std::vector<Vec6>&vel = s.vel, &acc = s.acc;
  std::vector<int>& cols = s.cols;
  d.resize(static_cast<size_t>(n));
  for (std::vector<Column>& column : d) column.clear();
  vel.resize(static_cast<size_t>(n));
  acc.resize(static_cast<size_t>(n));
  out.resize(static_cast<size_t>(n));
  for (NodeJacobian& column : out) column.clear();
  for (int k : dofs.order()) {
    const int j = dofs.joint_of(k);
    if (j < 0) {
      vel[size_t(k)] = NodeMotion(state, k, W);
      acc[size_t(k)] = NodeMotion(state, k, Wdot);
      continue;
    }
    const NodeJoint& joint = model.joints[size_t(j)];
    const int p = joint.parent, first = dofs.node_first(k), m = dofs.node_count(k);
    const ParentNode parent = ParentOf(state, p);
    const JointMaps maps = ComputeJointMaps(joint, parent.x, parent.R, state.x[k], state.z[k]);
    const JointVector zdot = W.segment(first, m), zddot = Wdot.segment(first, m);
    const Eigen::Vector3d rho = state.x[k] - parent.x, g = parent.R * joint.axis;
    static const Vec6 at_rest = Vec6::Zero();  // the ground's velocity and acceleration
    static const std::vector<Column> no_columns;
    const Vec6& vp = p == kGround ? at_rest : vel[size_t(p)];
    const Vec6& ap = p == kGround ? at_rest : acc[size_t(p)];
    const std::vector<Column>& dp = p == kGround ? no_columns : d[size_t(p)];
    const Eigen::Vector3d w = vp.tail<3>();
    const int is = joint.s_index(), ip = joint.phi_index();
    const bool universal = joint.type == JointType::kUniversal;
    const double sdot = is >= 0 ? zdot[is] : 0.0, phidot = ip >= 0 ? zdot[ip] : 0.0;
    Eigen::Vector3d g1 = Eigen::Vector3d::Zero(), g2 = Eigen::Vector3d::Zero();
    if (universal) g1 = maps.B.col(0).tail<3>(), g2 = maps.B.col(1).tail<3>();
    auto terms = [&](const Eigen::Vector3d& w_, const Eigen::Vector3d& rho_, const Eigen::Vector3d& g_,
                     const Eigen::Vector3d& g1_, const Eigen::Vector3d& g2_) {
      Vec6 t;
      t.head<3>() = w_.cross(w_.cross(rho_)) + 2 * sdot * w_.cross(g_);
      t.tail<3>() = phidot * w_.cross(g_);
      if (universal) t.tail<3>() += zdot[0] * w_.cross(g1_) + zdot[1] * (w_.cross(g2_) + zdot[0] * g1_.cross(g2_));
      return t;
    };
    vel[size_t(k)] = maps.A * vp + maps.B * zdot;
    acc[size_t(k)] = maps.A * ap + maps.B * zddot + terms(w, rho, g, g1, g2);
    // The coordinates that move this node's velocity or acceleration.
    cols.clear();
    for (const Column& c : dp) cols.push_back(c.col);
    for (const auto& [col, v] : parent.J)
      if (v.tail<3>().squaredNorm() > 0) cols.push_back(col);
    for (int i = 0; i < m; ++i) cols.push_back(first + i);
    std::sort(cols.begin(), cols.end());
    cols.erase(std::unique(cols.begin(), cols.end()), cols.end());
    for (int col : cols) {
      Vec6 dvp = Vec6::Zero(), dap = Vec6::Zero();
      for (const Column& c : dp)
        if (c.col == col) dvp = c.dvel, dap = c.dacc;
      Eigen::Vector3d dpi = Eigen::Vector3d::Zero();
      for (const auto& [c, v] : parent.J)
        if (c == col) dpi = v.tail<3>();
      JointVector dz = JointVector::Zero(m);
      if (col >= first && col < first + m) dz[col - first] = 1.0;
      const double ds = is >= 0 ? dz[is] : 0.0;  // an angle moves nothing here (universal: below)
      const Eigen::Vector3d drho = dpi.cross(rho) + ds * g, dg = dpi.cross(g);
      Eigen::Vector3d dg1 = Eigen::Vector3d::Zero(), dg2 = Eigen::Vector3d::Zero();
      if (universal) dg1 = dpi.cross(g1), dg2 = dpi.cross(g2) + dz[0] * g1.cross(g2);
      const Eigen::Vector3d dw = dvp.tail<3>();
      // d(B v) for v = zdot or zddot.
      auto dB = [&](const JointVector& v) {
        Vec6 r = Vec6::Zero();
        if (is >= 0) r.head<3>() += dg * v[is];
        if (ip >= 0) r.tail<3>() += dg * v[ip];
        if (universal) r.tail<3>() += dg1 * v[0] + dg2 * v[1];
        return r;
      };
      Vec6 dvel = maps.A * dvp + dB(zdot), dacc = maps.A * dap + dB(zddot);
      dvel.head<3>() += vp.tail<3>().cross(drho);
      dacc.head<3>() += ap.tail<3>().cross(drho);
      // d terms: linear in (w, rho, g, g1, g2) jointly quadratic; by their product rule.
      Vec6 dt;
      dt.head<3>() =
          dw.cross(w.cross(rho)) + w.cross(dw.cross(rho) + w.cross(drho)) + 2 * sdot * (dw.cross(g) + w.cross(dg));
      dt.tail<3>() = phidot * (dw.cross(g) + w.cross(dg));
      if (universal) {
        dt.tail<3>() += zdot[0] * (dw.cross(g1) + w.cross(dg1)) +
                        zdot[1] * (dw.cross(g2) + w.cross(dg2) + zdot[0] * (dg1.cross(g2) + g1.cross(dg2)));
      }
      dacc += dt;
      if (dvel.squaredNorm() == 0 && dacc.squaredNorm() == 0) continue;
      d[size_t(k)].push_back({col, dvel, dacc});
      if (dacc.squaredNorm() > 0) out[size_t(k)].emplace_back(col, dacc);
    }
  }
}

}  // namespace femb
