// The momenta of a free system under the midpoint scheme, kept through Newton's leftover and the
// round-off of the bodies' forces.
//
// Summed with a rigid motion of a free system at q_m, the scheme's balance (midpoint.cpp) gives
// over a step, with r the residual Newton stops at,
//   L_n+1 - L_n = h (resultant and moment of the applied forces at q_m) - h G_m^T r,
// L the linear and angular momentum about a fixed point o (Noether: the sums of the nodes'
// generalized momenta, MomentumFrom) and G_m the rigid motion (xi_v, xi_w) over the unknowns:
// a free node's translation xi_v + xi_w x (x_m - o) and rotation xi_w, a spherical joint's
// rotation xi_w; the other joints' coordinates are relative and the modal coordinates are taken
// from the floating frame, so both stay. The internal forces have no moment at q_m and a body's
// inertia force with a free node has that of its momenta's change (the source's construction):
// that is the scheme's conservation. Two things break it in floating point:
//  - Newton's leftover. Newton converges linearly here (its matrix leaves out O(omega h) terms of
//    the inertia), so r keeps much the same direction from step to step and its impulse
//    accumulates: a bar on one node spinning at 20 rad/s lost 1.1e-6 of its angular momentum
//    over 1 000 periods at the tolerance 1e-10, 5.7e-9 at 1e-12, linearly in time and in
//    proportion to the tolerance.
//  - The round-off of those two identities, of one sign in a steady spin: on two nodes at
//    200 rad/s the elastic force's moment summed to 5e-9 N m s over 50 000 steps (1.6e-11 of the
//    angular momentum), the source's to a fifth of that.
// At a converged step each free system's velocities therefore take the rigid increment G xi
// with A xi = h G_m^T r plus the two identities' defects as computed, A = G^T M_g G the system's
// locked inertia at q_n+1 from the same momenta the measurement sums: the momenta then change by
// exactly the applied impulses, to the round-off of that sum, whatever the tolerance. The
// increment is of the size of the tolerance times the forces' step impulse; the positions stay
// where Newton left them.
#include <Eigen/Dense>
#include <numeric>

#include "solver/analysis/dynamic_step.h"
#include "solver/body/inertia_force.h"

namespace femb::dynamic_internal {

namespace {

using Vector6 = Eigen::Matrix<double, 6, 1>;
using Matrix6 = Eigen::Matrix<double, 6, 6>;

int Root(std::vector<int>& parent, int i) {
  while (parent[size_t(i)] != i) i = parent[size_t(i)] = parent[size_t(parent[size_t(i)])];
  return i;
}

// The unknowns a rigid motion of node k's system moves: 2 for a free node (its 6), 1 for a
// spherical joint's child (its rotation's 3), 0 otherwise (a joint's relative coordinates).
int RigidRows(const SystemModel& model, const DofMap& dofs, int k) {
  const int j = dofs.joint_of(k);
  if (j < 0) return 2;
  return model.joints[size_t(j)].type == JointType::kSpherical ? 1 : 0;
}

// The rigid velocity xi at a node placed at x, the system's reference point at o.
Vector6 RigidVelocity(const Vector6& xi, const Eigen::Vector3d& x, const Eigen::Vector3d& o) {
  Vector6 v;
  v << xi.head<3>() + xi.tail<3>().cross(x - o), xi.tail<3>();
  return v;
}

// xi = A^+ b with A the locked inertia, scaled by the model's size L so that its translation and
// rotation blocks compare; directions without inertia (a massless system, point masses on a line
// about it) get no increment.
Vector6 SolveLocked(const Matrix6& A, const Vector6& b, double L) {
  Vector6 d;
  d << 1.0, 1.0, 1.0, 1.0 / L, 1.0 / L, 1.0 / L;
  const Matrix6 As = d.asDiagonal() * (0.5 * (A + A.transpose())) * d.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Matrix6> eigen(As);
  const Vector6& lambda = eigen.eigenvalues();
  const double floor = 1e-12 * lambda.cwiseAbs().maxCoeff();
  Vector6 y = eigen.eigenvectors().transpose() * d.cwiseProduct(b);
  for (int i = 0; i < 6; ++i) y[i] = lambda[i] > floor ? y[i] / lambda[i] : 0.0;
  return d.cwiseProduct(eigen.eigenvectors() * y);
}

}  // namespace

void FindFreeSystems(const SystemModel& model, const DofMap& dofs, MidpointWorkspace& mw) {
  // Nodes joined by joints, cut joints and bodies; the ground (index n) joined to joints' roots
  // there and to the nodes with a prescribed coordinate a rigid motion would move.
  const int n = model.n_nodes(), ground = n;
  std::vector<int> parent(size_t(n + 1));
  std::iota(parent.begin(), parent.end(), 0);
  const auto join = [&](int a, int b) { parent[size_t(Root(parent, a))] = Root(parent, b == kGround ? ground : b); };
  for (const NodeJoint& j : model.joints) join(j.child, j.parent);
  for (const CutJoint& c : model.cut_joints) join(c.joint.child, c.joint.parent);
  for (const std::vector<int>& nodes : model.body_nodes) {
    for (int k : nodes) join(k, nodes.front());
  }
  for (const SystemModel::Prescribed& p : model.prescribed) {
    if (RigidRows(model, dofs, p.node) > 0) join(p.node, kGround);
  }
  mw.system_of.assign(size_t(n), -1);
  mw.system_origin.clear();
  std::vector<int> system_of_root(size_t(n + 1), -1);
  const int grounded = Root(parent, ground);
  for (int k = 0; k < n; ++k) {
    const int root = Root(parent, k);
    if (root == grounded) continue;
    if (system_of_root[size_t(root)] < 0) {
      system_of_root[size_t(root)] = int(mw.system_origin.size());
      mw.system_origin.push_back(k);
    }
    mw.system_of[size_t(k)] = system_of_root[size_t(root)];
  }
}

void KeepMomenta(const SystemModel& model, const DofMap& dofs, double h, const Eigen::VectorXd& r, BodyWorkspace& work,
                 DynamicState& next) {
  MidpointWorkspace& mw = work.midpoint;
  std::vector<BodyPass>& passes = work.passes;
  const size_t n_systems = mw.system_origin.size();
  if (n_systems == 0) return;
  MidpointKinematics& k = mw.k;
  const auto origin = [&](int s) -> const Eigen::Vector3d& { return next.config.x[mw.system_origin[size_t(s)]]; };
  // The leftover's impulse h G_m^T r, at the mid configuration as the balance has it.
  mw.leftover.assign(n_systems, Vector6::Zero());
  for (int node = 0; node < model.n_nodes(); ++node) {
    const int s = mw.system_of[size_t(node)], rows = RigidRows(model, dofs, node), first = dofs.node_first(node);
    if (s < 0 || rows == 0) continue;
    Vector6& b = mw.leftover[size_t(s)];
    if (rows == 2) {
      const Eigen::Vector3d f = r.segment<3>(first);
      b.head<3>() += h * f;
      b.tail<3>() += h * (r.segment<3>(first + 3) + (k.mid.x[size_t(node)] - origin(s)).cross(f));
    } else {
      b.tail<3>() += h * r.segment<3>(first);
    }
  }
  // What each body's own terms hold against their identities at round-off: the moment of its
  // internal force, and with a free node the source's (its inertia force's moment less the change
  // of its momenta).
  for (size_t bi = 0; bi < model.bodies.size(); ++bi) {
    const std::vector<int>& nodes = model.body_nodes[bi];
    const int s = nodes.empty() ? -1 : mw.system_of[size_t(nodes.front())];
    if (s < 0) continue;
    const BodyTerms& terms = work.terms[bi];
    MidpointBody& m = mw.bodies[bi];
    const Eigen::Vector3d& o = origin(s);
    Vector6 defect = Vector6::Zero();
    for (size_t a = 0; a < nodes.size(); ++a) {
      const Eigen::Index row = 6 * Eigen::Index(a);
      const Eigen::Vector3d arm = k.mid.x[size_t(nodes[a])] - o;
      Eigen::Vector3d f = terms.f_int.segment<3>(row);
      defect.head<3>() += f;
      defect.tail<3>() += terms.f_int.segment<3>(row + 3) + arm.cross(f);
      if (!mw.free_node[bi]) continue;
      f = terms.f_in.segment<3>(row);
      defect.head<3>() += f;
      defect.tail<3>() += terms.f_in.segment<3>(row + 3) + arm.cross(f);
    }
    defect *= h;
    if (mw.free_node[bi]) {
      Eigen::Vector3d linear, angular;
      MomentumFrom(model.bodies[bi], passes[bi].data, m.p1, &linear, &angular);
      defect.head<3>() -= linear;
      defect.tail<3>() -= angular - o.cross(linear);
      MomentumFrom(model.bodies[bi], m.d0, m.p0, &linear, &angular);
      defect.head<3>() += linear;
      defect.tail<3>() += angular - o.cross(linear);
    }
    mw.leftover[size_t(s)] += defect;
  }
  // Each body's share of its system's locked inertia: the momenta of the 6 unit rigid velocities
  // of its nodes at n+1 (the body's data there are its converged pass's).
  mw.locked.assign(n_systems, Matrix6::Zero());
  for (size_t bi = 0; bi < model.bodies.size(); ++bi) {
    const std::vector<int>& nodes = model.body_nodes[bi];
    const int s = nodes.empty() ? -1 : mw.system_of[size_t(nodes.front())];
    if (s < 0) continue;
    const SuperelementBody& body = model.bodies[bi];
    BodyData& data = passes[bi].data;
    Eigen::VectorXd& w = mw.bodies[bi].rigid;
    w.setZero(body.n_coordinates());
    for (int i = 0; i < 6; ++i) {
      for (size_t a = 0; a < nodes.size(); ++a) {
        w.segment<6>(6 * Eigen::Index(a)) = RigidVelocity(Vector6::Unit(i), next.config.x[size_t(nodes[a])], origin(s));
      }
      Eigen::Vector3d linear, angular;
      MomentumFrom(body, data, MassTimes(body, data, w), &linear, &angular);
      mw.locked[size_t(s)].col(i) += (Vector6() << linear, angular - origin(s).cross(linear)).finished();
    }
  }
  // The increments: into W (free nodes, spherical rotations), the node velocities, the bodies'.
  const double L = std::sqrt(mw.L2) > 0 ? std::sqrt(mw.L2) : 1.0;
  for (size_t s = 0; s < n_systems; ++s) mw.leftover[s] = SolveLocked(mw.locked[s], mw.leftover[s], L);
  for (int node = 0; node < model.n_nodes(); ++node) {
    const int s = mw.system_of[size_t(node)], rows = RigidRows(model, dofs, node), first = dofs.node_first(node);
    if (s < 0) continue;
    const Vector6& xi = mw.leftover[size_t(s)];
    const Vector6 v = RigidVelocity(xi, next.config.x[size_t(node)], origin(s));
    k.node_w1[size_t(node)] += v;
    if (rows == 2) next.W.segment<6>(first) += v;
    if (rows == 1) next.W.segment<3>(first) += xi.tail<3>();
  }
  for (size_t bi = 0; bi < model.bodies.size(); ++bi) {
    const std::vector<int>& nodes = model.body_nodes[bi];
    const int s = nodes.empty() ? -1 : mw.system_of[size_t(nodes.front())];
    if (s < 0) continue;
    for (size_t a = 0; a < nodes.size(); ++a) {
      passes[bi].w.segment<6>(6 * Eigen::Index(a)) +=
          RigidVelocity(mw.leftover[size_t(s)], next.config.x[size_t(nodes[a])], origin(s));
    }
  }
}

}  // namespace femb::dynamic_internal
