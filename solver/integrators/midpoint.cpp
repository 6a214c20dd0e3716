#include <Eigen/Dense>
#include <cmath>

#include "solver/analysis/dynamic_step.h"
#include "solver/rotation.h"

namespace femb::dynamic_internal {

// ---- Momentum-conserving midpoint scheme ---------------------------------------------------
//
// Per step (Simo & Wong 1991 for the rigid body; free nodes move as on SE(3)):
//   kinematics   node rotations: R_n+1 = R_n exp(h Omega_m~), Omega_m = (Omega_n + Omega_n+1) / 2
//                (Omega = R^T omega, convected); free nodes also x_n+1 = x_n + R_n J_l(h Omega_m)
//                h V_m, V_m = (V_n + V_n+1) / 2, V = R^T xdot (a rigid motion of constant twist is
//                then exact for every node of a body); every other coordinate
//                z_n+1 - z_n = h (W_n + W_n+1) / 2.
//   mid config   q_m: half the step on the same curves (SE(3) geodesic midpoint for free nodes,
//                rotations exp(Delta_pi / 2) R_n, z_n + Delta / 2). The chord midpoint would make
//                a spinning body look compressed by (omega h)^2 / 8 of its radius: 500 N of
//                spurious axial force in a 1 m tube at 20 rad/s and 200 steps per turn. The
//                nodes of a free flexible body whose energy is closed sit (omega h)^2 / 24 of its
//                size nearer (ScrewMidShift), where a rigid step is a rigid motion.
//   balance      per body, mapped by the node Jacobians at q_m:
//                (p_n+1 - p_n) / h - [s(q_m, w_b, p_n) + s(q_m, w_a, p_n+1)] / 2
//                    = f_ext(q_m, t_m) - f_int(q_m),
//                p = M_g w (generalized momentum), s = MomentumSource (superelement_body.h), w_b,
//                w_a the node motion of the two half steps: translations 2 (x_m - x_n) / h and
//                2 (x_n+1 - x_m) / h, rotations log(R_n+1 R_n^T) / h.
// s has no resultant and its moment about the origin is sum_k p_x,k x xdot_k, so the source's
// moment equals minus the change of sum_k x_k x p_x,k over the two half steps, and the forces at
// q_m have no moment: the linear and angular momentum of a free system are conserved exactly,
// flexible bodies included. For a rigid body this is Simo & Wong's scheme and the kinetic energy
// is conserved too; a free flexible body on several nodes takes an energy closure that makes it
// exact as well (midpoint_energy.cpp); for a flexible body on joints or with the inertia
// stiffening the energy error is second order and small. No numerical damping.
//
// Chains of joints (nodes that are functions of other nodes' coordinates) get three more
// pieces, so that a chain or loop of rigid bodies keeps its energy exactly too:
// such nodes carry their own velocities (EndNodeVelocity), the node Jacobians at q_m and gravity
// are discrete gradients (AddDiscreteGradientCorrection, the gravity term in AssembleMidpoint),
// and bodies without a free node take the source at the mean motion. See each for why.

std::vector<RotationNode> RotationNodes(const SystemModel& model, const DofMap& dofs) {
  std::vector<RotationNode> nodes;
  for (int k = 0; k < model.n_nodes(); ++k) {
    const int j = dofs.joint_of(k);
    if (j < 0) {
      nodes.push_back({k, dofs.node_first(k) + 3, dofs.node_first(k)});  // free
    } else if (model.joints[j].type == JointType::kSpherical) {
      nodes.push_back({k, dofs.node_first(k), -1});
    }
  }
  return nodes;
}

namespace {

// The velocity at n+1 of a node that hangs on joints, from its motion over the step and its
// velocity at n: xdot_n+1 = 2 (x_n+1 - x_n) / h - xdot_n and, as for a rotation node (Simo & Wong),
// omega_n+1 = R_n+1 (2 Omega_m - R_n^T omega_n), Omega_m = R_n^T log(R_n+1 R_n^T) / h. This is not
// J(q_n+1) W_n+1 (the two differ by O(h^2), without accumulating), but it is what the bodies'
// momentum balance pairs with their kinetic energy: with J(q) W at both ends a chain of joints
// drifts as O(h^2) (a rigid four-bar under gravity 1.5e-5 of its energy over 10 s at h = 1 ms).
// The scheme carries these node velocities from step to step (DynamicState::node_w), as the
// discrete null space method carries redundant velocities (Betsch & Leyendecker, Int. J. Numer.
// Meth. Engng 67, 2006). Nodes with their own coordinates (free nodes, supports) keep W's.
// `step`: the node's NodeStep.
Eigen::Matrix<double, 6, 1> EndNodeVelocity(const Eigen::Matrix3d& R0, const Eigen::Matrix3d& R1,
                                            const Eigen::Matrix<double, 6, 1>& step,
                                            const Eigen::Matrix<double, 6, 1>& w0, double h) {
  const Eigen::Vector3d Omega_m = R0.transpose() * step.tail<3>() / h;
  Eigen::Matrix<double, 6, 1> w1;
  w1 << 2.0 * step.head<3>() / h - w0.head<3>(), R1 * (2.0 * Omega_m - R0.transpose() * w0.tail<3>());
  return w1;
}

// A node's motion over the step, (x_n+1 - x_n, log(R_n+1 R_n^T)): what the bodies' balance pairs
// with their energy, and what the forces' discrete gradients are made to work along.
Eigen::Matrix<double, 6, 1> NodeStep(const SystemState& c0, const SystemState& c1, int node) {
  Eigen::Matrix<double, 6, 1> m;
  m << c1.x[node] - c0.x[node], LogSO3(c1.R[node] * c0.R[node].transpose());
  return m;
}

Eigen::Matrix<double, 6, 1> NodeVelocity(const DynamicState& s, int node) {
  return s.node_w.empty() ? NodeMotion(s.config, node, s.W) : s.node_w[size_t(node)];
}

}  // namespace

// The step's kinematics (MidpointKinematics) at the end state s1, into k; sets s1's end velocities.
void Midpoint(const SystemModel& model, const DofMap& dofs, const std::vector<RotationNode>& nodes,
              const DynamicState& s0, double h, DynamicState& s1, MidpointKinematics& k) {
  const int n = dofs.n_dofs();
  k.node_step.resize(size_t(model.n_nodes()));
  for (int node = 0; node < model.n_nodes(); ++node) k.node_step[size_t(node)] = NodeStep(s0.config, s1.config, node);
  k.delta.setZero(n);
  for (int node = 0; node < model.n_nodes(); ++node) {
    if (dofs.node_count(node) > 0) {
      k.delta.segment(dofs.node_first(node), dofs.node_count(node)) = s1.config.z[node] - s0.config.z[node];
    }
  }
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    k.delta.segment(dofs.mode_dof(int(b)), model.bodies[b].n_modes()) = s1.config.eta[b] - s0.config.eta[b];
  }
  // Every other coordinate: z_n+1 - z_n = h (W_n + W_n+1) / 2, z_m = z_n + Delta / 2.
  Eigen::VectorXd& W1 = k.W1;
  W1 = 2.0 / h * k.delta - s0.W;
  k.half = 0.5 * k.delta;
  k.T.diagonal = 0.5;
  k.V.diagonal = 2.0 / h;
  for (StepColumnMap* X : {&k.T, &k.V}) {
    X->rotation.resize(nodes.size());
    X->translation.resize(nodes.size());
    X->coupling.resize(nodes.size());
  }
  for (size_t i = 0; i < nodes.size(); ++i) {
    const RotationNode& r = nodes[i];
    const Eigen::Matrix3d& R0 = s0.config.R[r.node];
    const Eigen::Matrix3d& R1 = s1.config.R[r.node];
    const Eigen::Vector3d dpi = k.node_step[size_t(r.node)].tail<3>();
    k.delta.segment<3>(r.rotation) = dpi;
    k.half.segment<3>(r.rotation) = 0.5 * dpi;
    const Eigen::Vector3d Omega_m = R0.transpose() * dpi / h;
    const Eigen::Vector3d omega1 = R1 * (2.0 * Omega_m - R0.transpose() * s0.W.segment<3>(r.rotation));
    W1.segment<3>(r.rotation) = omega1;
    // An end increment delta (R_n+1 <- exp(delta~) R_n+1) changes Delta_pi by J_l^-1(Delta_pi)
    // delta: the mid rotation exp(Delta_pi~ / 2) R_n by A delta / 2, A = J_l(Delta_pi / 2)
    // J_l^-1(Delta_pi), and omega_n+1 by [2/h R_n+1 R_n^T J_l^-1(Delta_pi) - omega_n+1~] delta.
    const Eigen::Matrix3d Jinv = LeftJacobianInverse<double>(dpi);
    const Eigen::Matrix3d A = LeftJacobianInverse<double>(Eigen::Vector3d(0.5 * dpi)).inverse() * Jinv;
    k.T.rotation[i] = 0.5 * A;
    k.V.rotation[i] = 2.0 / h * R1 * R0.transpose() * Jinv - Skew<double>(omega1);
    if (r.translation < 0) continue;
    // Free node: the step is the SE(3) exponential of the mean convected twist (V, Omega),
    // V = R^T xdot: x_n+1 = x_n + R_n J_l(h Omega_m) h V_m. A rigid motion of constant twist is
    // then exact for every node of a body (chords and rotations agree).
    const Eigen::Vector3d dx = k.delta.segment<3>(r.translation);
    const Eigen::Matrix3d Jinv_step = LeftJacobianInverse<double>(Eigen::Vector3d(h * Omega_m));
    const Eigen::Vector3d V_m = Jinv_step * (R0.transpose() * dx) / h;
    const Eigen::Vector3d xdot1 = R1 * (2.0 * V_m - R0.transpose() * s0.W.segment<3>(r.translation));
    W1.segment<3>(r.translation) = xdot1;
    // Mid configuration on the same SE(3) geodesic (not the chord midpoint: at the chord
    // midpoint a spinning body would look compressed, by (omega h)^2 / 8 of its radius). In
    // spatial form x_m - x_n = A Delta_x / 2; its change with the end rotation is Delta_x~ / 8
    // to first order.
    const Eigen::Matrix3d J_half = LeftJacobianInverse<double>(Eigen::Vector3d(0.5 * h * Omega_m)).inverse();
    k.half.segment<3>(r.translation) = R0 * (J_half * (0.5 * h * V_m));
    k.T.translation[i] = 0.5 * A;
    k.T.coupling[i] = Skew<double>(dx) / 8.0;
    if (!k.screw_mid.empty() && k.screw_mid[size_t(r.node)]) {
      ScrewMidShift(dpi, dx, Jinv, k.half.segment<3>(r.translation), k.T.translation[i], k.T.coupling[i]);
    }
    // xdot_n+1: 2/h R_n+1 J_l^-1(h Omega_m) R_n^T per end translation; per end rotation
    // -xdot_n+1~ (turning R_n+1) + R_n+1 V_m~ R_n^T (through Omega_m), to first order.
    k.V.translation[i] = 2.0 / h * R1 * Jinv_step * R0.transpose();
    k.V.coupling[i] = -Skew<double>(xdot1) + R1 * Skew<double>(V_m) * R0.transpose();
  }
  // End velocities from the kinematics (prescribed coordinates keep their given rates).
  for (int j : dofs.solved()) s1.W[j] = W1[j];
  // Node velocities at n+1 (after W_n+1: free nodes and supports take theirs from it).
  k.node_w1.resize(size_t(model.n_nodes()));
  for (int node = 0; node < model.n_nodes(); ++node) {
    k.node_w1[size_t(node)] = dofs.joint_of(node) < 0
                                  ? NodeMotion(s1.config, node, s1.W)
                                  : EndNodeVelocity(s0.config.R[node], s1.config.R[node], k.node_step[size_t(node)],
                                                    NodeVelocity(s0, node), h);
  }
  k.mid = s0.config;
  ApplyIncrement(model, dofs, k.half, k.mid);
}

namespace {

// The node forces f_k (everything a node receives: bodies' inertia, internal and gravity forces,
// loads, springs, loop forces) act on the coordinates through the node Jacobians at q_m, so over
// the step they do the work sum_k f_k . J_k(q_m) Delta. The nodes moved m_k = (x_n+1 - x_n,
// log(R_n+1 R_n^T)), which is what the bodies' momentum balance pairs with its energy. For a node
// that hangs on joints the two differ by O(h^3) (its Jacobian turns along the step), an O(h^2)
// energy drift over a run. Gonzalez's discrete gradient (J. Nonlinear Sci. 6, 1996) closes the
// gap: J_d = J_m + (m - J_m Delta) Delta^T D / (Delta^T D Delta) has J_d Delta = m exactly, and
// J_d^T f = J_m^T f + D Delta (sum_k (m_k - J_k Delta) . f_k) / (Delta^T D Delta). D weighs a
// coordinate by how far it moves the nodes (rotations times the model's size L); modal
// coordinates and free nodes map exactly and get nothing. The correction is O(h^2) of the forces
// and is left out of the iteration matrix.
void AddDiscreteGradientCorrection(const SystemModel& model, const DofMap& dofs, const MidpointKinematics& k, double L2,
                                   MidpointWorkspace& w, Assembly& out) {
  if (model.joints.empty()) return;
  const int n = dofs.first_multiplier();
  Eigen::VectorXd& D = w.D;
  D.setZero(n);
  double gap_work = 0.0;
  for (int node = 0; node < model.n_nodes(); ++node) {
    if (dofs.joint_of(node) < 0) continue;
    Eigen::Matrix<double, 6, 1> gap = k.node_step[size_t(node)];
    for (const auto& [col, vec] : k.mid.J[node]) {
      gap -= vec * k.delta[col];
      D[col] += vec.head<3>().squaredNorm() + L2 * vec.tail<3>().squaredNorm();
    }
    gap_work += gap.dot(out.node_forces.f[node]);
  }
  Eigen::VectorXd& Dd = w.Dd;
  Dd = D.cwiseProduct(k.delta.head(n));
  const double norm = Dd.dot(k.delta.head(n));
  if (!(norm > 0)) return;
  out.residual.head(n) += Dd * (gap_work / norm);
}

// Residual (applied minus inertia and internal forces, over the coordinates) of the midpoint
// balance, into `out`; each body's data at both configurations kept for the iteration matrix
// (MidpointMatrix), which an iteration builds only when it needs one. The momenta at the step's
// start are in work.midpoint.bodies (MidpointStep).
// A body's inertia force of the step into r.f_in (and its acceleration part M_g (w1 - w0) / h into
// r.f_acc): the change of its momenta over the step less the momentum source. d1, w1, maps1: the
// body's data, velocities and corotational velocity maps at the end of the step.
void MidpointInertia(const SystemModel& model, const DynamicState& s0, double h, const DynamicState& s1, int b,
                     BodyData& d1, const Eigen::VectorXd& w1, const BodyVelocityMaps& maps1, MidpointWorkspace& mw,
                     BodyTerms& r) {
  const SuperelementBody& body = model.bodies[b];
  const MidpointKinematics& k = mw.k;
  MidpointBody& m = mw.bodies[size_t(b)];
  BodyData& dm = m.dm;
  const Eigen::VectorXd& wm = m.wm;
  const bool exact = body.has_exact_inertia();
  Eigen::VectorXd &f_in = r.f_in, &f_acc = r.f_acc;
  m.dw = w1 - m.w0;
  f_acc.resize(body.n_coordinates());
  if (exact) {
    f_acc = MassTimes(body, d1, m.dw);
  } else {
    f_acc.noalias() = maps1.Mg * m.dw;
  }
  f_acc /= h;
  m.p_mean = 0.5 * (m.p0 + m.p1);  // (also for the source's derivatives in the matrices)
  if (body.options().quadratic_velocity_terms) {
    // Source terms with the node motion of each half step, so that their moment matches the
    // change of sum x_k x p_k exactly: x_m is not the mean of x_n and x_n+1.
    if (mw.free_node[size_t(b)]) {
      m.w_second = wm;
      m.w_first = wm;
      for (int a = 0; a < body.n_nodes(); ++a) {
        const int node = model.body_nodes[b][a];
        m.w_second.segment<3>(6 * a) = 2.0 * (s1.config.x[node] - k.mid.x[node]) / h;
        m.w_first.segment<3>(6 * a) = 2.0 * (k.mid.x[node] - s0.config.x[node]) / h;
      }
      MomentumSource(body, dm, m.w_second, m.p1, m.s_second);
      MomentumSource(body, dm, m.w_first, m.p0, m.s_first);
      f_in = (m.p1 - m.p0) / h - 0.5 * (m.s_second + m.s_first);
    } else {
      // No free node: every node hangs on joints or supports. The source at the step's mean
      // motion and mean momentum does no work for a rigid body, s(wm, p_m) . wm =
      // (wm~ U wm) . M wm = 0 with trapezoidal node velocities, so the energy of a chain of
      // rigid bodies is conserved to Newton's tolerance (four-bar under gravity: 4e-10 over
      // 10 s, against 1.5e-5 with the split source). The price: the moment of this source
      // no longer matches the change of sum x_k x p_k exactly, so a chain whose root floats
      // free keeps its angular momentum to O(h^2) only (a grounded chain has none to keep).
      // Energy is the invariant a mechanism on joints is judged by.
      MomentumSource(body, dm, wm, m.p_mean, m.s_first);
      f_in = (m.p1 - m.p0) / h - m.s_first;
    }
  } else {
    f_in = f_acc;
  }
}

// Gravity on a body as a discrete gradient of its potential V = -m g . x_c (Gonzalez), into
// f_grav: its work over the step's motion u = h wm is exactly V_n - V_n+1, where the force at q_m
// alone is off by O(h^3) (x_c turns with the frame). The correction lies along D u, D = 1 on node
// translations and the model's size squared on node rotations. q1, f1: the end state's local
// coordinates and frame.
void MidpointGravity(const SystemModel& model, double h, int b, const Eigen::VectorXd& q1, const FrameSolution& f1,
                     MidpointWorkspace& mw, Eigen::VectorXd& f_grav) {
  const SuperelementBody& body = model.bodies[b];
  MidpointBody& m = mw.bodies[size_t(b)];
  BodyData& dm = m.dm;
  const Eigen::VectorXd& wm = m.wm;
  if (model.gravity.squaredNorm() > 0) {
    GravityForce(body, dm, model.gravity, f_grav);
    Eigen::VectorXd &u = m.u, &Du = m.Du;
    u = h * wm;
    const double dV = -body.mass() * model.gravity.dot(CenterOfMass(body, q1, f1) - m.com0);
    Du.setZero(u.size());
    for (int a = 0; a < body.n_nodes(); ++a) {
      Du.segment<3>(6 * a) = u.segment<3>(6 * a);
      Du.segment<3>(6 * a + 3) = mw.L2 * u.segment<3>(6 * a + 3);
    }
    const double norm = Du.dot(u);
    if (norm > 0) f_grav += Du * ((-dV - f_grav.dot(u)) / norm);
    mw.gravity_work[size_t(b)] = -dV;
  } else {
    f_grav.setZero(body.n_coordinates());
  }
}

}  // namespace

// One body's terms of the midpoint balance (BodyTerms): its frames at the end and mid
// configurations, end velocities, inertia force, internal force at q_m (with the inertia
// stiffening at the step's mean velocity and acceleration), gravity, scales, map at q_m.
void MidpointBodyTerms(const SystemModel& model, const DofMap& dofs, const DynamicState& s0, double h, DynamicState& s1,
                       int b, BodyWorkspace& work) {
  MidpointWorkspace& mw = work.midpoint;
  MidpointKinematics& k = mw.k;
  const SuperelementBody& body = model.bodies[b];
  BodyTerms& r = work.terms[size_t(b)];
  BodyPass& pass = work.passes[size_t(b)];
  MidpointBody& m = mw.bodies[size_t(b)];
  BodyData &d1 = pass.data, &dm = m.dm;
  r.frame_ok = true;
  BodyConfigurationOf(model, s1.config, b, d1.c);
  BodyConfigurationOf(model, k.mid, b, dm.c);
  const FrameSolution f1 = PlaceBody(body, s1.config.frames[b], d1);
  const FrameSolution fm = f1.ok ? PlaceBody(body, s0.config.frames[b], dm) : FrameSolution{};
  if (!f1.ok || !fm.ok) {
    r.frame_ok = false;
    return;
  }
  s1.config.frames[b] = f1;
  k.mid.frames[b] = fm;
  Eigen::VectorXd& w1 = pass.w;
  w1.resize(body.n_coordinates());
  for (int a = 0; a < body.n_nodes(); ++a) w1.segment<6>(6 * a) = k.node_w1[size_t(model.body_nodes[b][a])];
  w1.tail(body.n_modes()) = s1.W.segment(dofs.mode_dof(int(b)), body.n_modes());
  // Velocity maps at the end and at the mid configuration, shared by the momentum terms.
  const BodyVelocityMaps& maps1 = MapsOf(body, d1);
  // The momenta of the body's kinetic energy, p = dT/dw (the exact inertia's or M_g w).
  const bool exact = body.has_exact_inertia();
  m.p1.resize(body.n_coordinates());
  if (exact) {
    m.p1 = MassTimes(body, d1, w1);
  } else {
    m.p1.noalias() = maps1.Mg * w1;
  }
  // Node motion over the step.
  Eigen::VectorXd& wm = m.wm;
  wm.resize(body.n_coordinates());
  for (int a = 0; a < body.n_nodes(); ++a) wm.segment<6>(6 * a) = k.node_step[size_t(model.body_nodes[b][a])] / h;
  wm.tail(body.n_modes()) = (s1.config.eta[b] - s0.config.eta[b]) / h;
  Eigen::VectorXd &f_in = r.f_in, &f_int = r.f_int, &f_acc = r.f_acc;
  MidpointInertia(model, s0, h, s1, b, d1, w1, maps1, mw, r);
  const bool closes = mw.closes[size_t(b)];
  if (closes) m.F = f_in;
  AddModalDamping(body, wm, f_in, nullptr);
  // Inertia stiffening at the mid configuration with the step's mean velocity and acceleration.
  m.wdot = m.dw / h;
  if (closes) {
    AveragedElasticForce(body, d1, m, f_int);
    CloseEnergy(body, h, d1, w1, m, f_int);
  } else {
    StiffenedElasticForce(body, dm, wm, m.wdot, model.gravity, m.load, f_int);
  }
  Eigen::VectorXd& f_grav = r.f_grav;
  MidpointGravity(model, h, b, d1.q, f1, mw, f_grav);
  // Scale: each term on its own (for a torque-free body the momentum change and the source
  // cancel; M_g (w_n+1 - w_n) / h is the size of the inertia force).
  r.scale = std::max(
      {body.ForceNorm(f_int), body.ForceNorm(f_in), body.ForceNorm(f_grav), body.force_floor(), body.ForceNorm(f_acc)});
  r.roundoff = RoundOffForce(body, d1.c, work.inertia_factor);
  BodyMap(model, dofs, k.mid, int(b), r.map);
  r.r_b = f_grav - f_int - f_in;
}

namespace {

void AssembleMidpoint(const SystemModel& model, const DofMap& dofs, const DynamicState& s0, double h, DynamicState& s1,
                      BodyWorkspace& work, BodyThreads* threads, Assembly& out) {
  MidpointWorkspace& mw = work.midpoint;
  MidpointKinematics& k = mw.k;
  AssemblyParts& parts = work.parts;
  StartAssembly(model, dofs, parts, out);
  // Each body into its slot (on the threads), then added in body order.
  const int n_bodies = int(model.bodies.size());
  work.passes.resize(size_t(n_bodies));
  work.terms.resize(size_t(n_bodies));
  work.pass_data.resize(size_t(n_bodies));
  mw.mid_data.resize(size_t(n_bodies));
  for (int b = 0; b < n_bodies; ++b) {
    work.pass_data[size_t(b)] = &work.passes[size_t(b)].data;
    mw.mid_data[size_t(b)] = &mw.bodies[size_t(b)].dm;
  }
  mw.gravity_work.assign(size_t(n_bodies), 0.0);
  ForEachBody(threads, n_bodies, [&](int b) { MidpointBodyTerms(model, dofs, s0, h, s1, b, work); });
  if (!AddBodyTerms(model, work.terms, parts, out)) return;
  // Closed loops: the constraint forces -G^T lambda_n+1 at the mid configuration (their work
  // over the step, lambda . G(q_m) Delta, is lambda . (g_n+1 - g_n) = 0 up to O(h^3)); the
  // equations themselves hold at the end of the step (MidpointStep).
  k.mid.lambda = s1.config.lambda;
  AddLoopConstraints(model, dofs, k.mid, &out.residual, nullptr, &parts.node_forces, nullptr, kLoopAll, &mw.mid_data,
                     &parts.scratch);
  // Loads at the mid time and configuration, spring-dampers at the mean rates Delta / h.
  mw.rates = k.delta / h;
  FinishAssembly(model, dofs, k.mid, s0.t + 0.5 * h, mw.rates, false, parts, out);
  AddDiscreteGradientCorrection(model, dofs, k, mw.L2, mw, out);
}

// The external work of the step at the iterate just assembled, as the forces' discrete gradients
// do it: gravity's potential change, and the nodal loads (at q_m) times the nodes' motion.
double StepExternalWork(const SystemModel& model, const DofMap& dofs, double t_mid, MidpointWorkspace& mw) {
  double work = 0.0;
  for (double w : mw.gravity_work) work += w;
  const bool modal = !model.user_modal_forces.empty();
  if (model.loads.empty() && model.user_forces.empty() && !modal) return work;
  mw.loads.f.assign(size_t(model.n_nodes()), Eigen::Matrix<double, 6, 1>::Zero());
  mw.unused.setZero(dofs.n_dofs());
  // The user's forces evaluated once: on nodes into mw.loads, on modal coordinates into their rows
  // of mw.unused, whose work is Q at the midpoint times the modal coordinates' step.
  AddUserForces(model, mw.k.mid, mw.rates, t_mid, modal ? &mw.unused : nullptr, nullptr, nullptr, &mw.loads);
  for (size_t b = 0; modal && b < model.bodies.size(); ++b) {
    const int first = dofs.mode_dof(int(b)), n = model.bodies[b].n_modes();
    if (n > 0) work += mw.unused.segment(first, n).dot(mw.k.delta.segment(first, n));
  }
  AddNodeLoads(model, mw.k.mid, t_mid, mw.unused, nullptr, &mw.loads);
  for (int node = 0; node < model.n_nodes(); ++node) work += mw.k.node_step[size_t(node)].dot(mw.loads.f[size_t(node)]);
  return work;
}

// The iteration matrix S = K T + (C + M V) / h of the residual pass `a` just made (the same
// iterate): Newton's increment delta at n+1 moves W_n+1 by V delta, q_m by T delta and the step's
// motion w_m by ~delta / h. Each body's K, C, M at the pass's data (on the threads, added in body
// order), the loads', spring-dampers' and joints' blocks, the loops'; built from triplets.
const SystemMatrix& MidpointMatrix(const SystemModel& model, const DofMap& dofs, const DynamicState& s0, double h,
                                   const DynamicState& s1, BodyWorkspace& work, BodyThreads* threads,
                                   const Assembly& a) {
  MidpointWorkspace& mw = work.midpoint;
  const MidpointKinematics& k = mw.k;
  const std::vector<RotationNode>& triples = work.rotation_triples;
  const int n_bodies = int(model.bodies.size());
  work.matrices.resize(size_t(n_bodies));
  ForEachBody(threads, n_bodies, [&](int b) {
    const SuperelementBody& body = model.bodies[b];
    BodyPass& pass = work.passes[size_t(b)];
    MidpointBody& m = mw.bodies[size_t(b)];
    BodyWorkspace::BodyMatrices& r = work.matrices[size_t(b)];
    const bool stiffening = body.has_inertia_stiffening();
    ElasticForce(body, m.dm, nullptr, &r.K, stiffening ? &m.load : nullptr, stiffening ? &r.d_load : nullptr);
    if (mw.closes[size_t(b)]) AveragedElasticTangent(body, pass.data, m, r.K, m.K_end);
    // M_g at the end of the step: the 2/h^2 term of the iteration matrix is d p_n+1 / h; at
    // the mid configuration it would be off by O(omega h) and leave a 1/h error.
    r.M = Mass(body, pass.data);
    if (body.options().quadratic_velocity_terms) {
      // With dp_n+1 = (M_g V + D) delta (V = d W_n+1 / d delta ~ 2/h, D = d p / dq at fixed w)
      // and dw_a ~ delta / h,
      //   d f_in / d delta = [M_g V + D - d_w s(p_mean) - (d_p s) M_g] / h + O(1).
      // All the 1/h terms are needed (and M_g at n+1, V with its O(omega) part): each is
      // O(omega h) of the leading one, and without them Newton contracts only by ~omega h per
      // iteration, or worse on stiff, lightly inertial directions such as a tube's torsion.
      // The exact inertia: d p_n+1 / dq by differences (MomentumConfigurationTangent); the
      // source's local term's derivatives, O(omega h) of the rest, are left to the iterations.
      MomentumSourceDerivatives(body, MapsOf(body, m.dm), m.wm, m.p_mean, m.d_w, m.d_p, m.dm.scratch);
      AddLocalSourceVelocityDerivative(body, m.dm, m.wm, m.d_w);
      MomentumConfigurationTangent(body, pass.data, pass.w, m.side, r.C);
      r.C -= m.d_w;
      r.C.noalias() -= m.d_p * r.M;
    } else {
      r.C.setZero(body.n_coordinates(), body.n_coordinates());
    }
    r.unused.setZero(body.n_coordinates());
    AddModalDamping(body, m.wm, r.unused, &r.C);
    if (stiffening) {
      // The inertia loads' velocity and acceleration derivatives: d wm = delta / h (into C / h)
      // and d (w1 - w0) / h = V delta / h (into M V / h).
      r.C.noalias() += r.d_load * m.load.d_w;
      r.M.noalias() += r.d_load * m.load.d_wdot;
    }
  });
  // T = T_d 1 + T', V = V_d 1 + V' with T', V' on the rotation nodes' triples only, so a body's
  // share B^T (K B T + C B / h + M B V / h) is B^T S_b B, S_b = T_d K + C / h + V_d / h M combined
  // here (one scatter instead of three), plus K and M through T' and V' on the columns of its
  // rotation-node coordinates (AddRotationColumns).
  Triplets& S = mw.S;
  S.clear();
  for (int b = 0; b < n_bodies; ++b) {
    BodyWorkspace::BodyMatrices& r = work.matrices[size_t(b)];
    const std::vector<MapEntry>& map = work.terms[size_t(b)].map;  // the residual pass's, at q_m
    Eigen::MatrixXd& S_b = mw.bodies[size_t(b)].S_b;
    S_b = k.T.diagonal * r.K + (1.0 / h) * r.C + (k.V.diagonal / h) * r.M;
    // An energy closure's derivative: computed at a step's first matrix (or kept from the last
    // step where that converged in fewer than 4 iterations) and again after a correction that
    // contracted the residual less than tenfold (MidpointStep), kept between.
    MidpointBody& m = mw.bodies[size_t(b)];
    if (mw.closes[size_t(b)]) S_b += m.K_end;
    if (m.closure_on) {
      if (!m.dc_fresh) EnergyClosureGradient(model, dofs, s0, h, s1, b, work);
      m.dc_fresh = true;
      S_b += m.dc;
    }
    ScatterBody(map, nullptr, &S_b, nullptr, &S);
    AddRotationColumns(map, r.K, r.M, h, k, triples, mw.triple_of, S);
  }
  // Loads at the mid time and configuration, spring-dampers at the mean rates Delta / h, the
  // joints' geometric stiffness with the pass's node forces: through T and V whole.
  Triplets &K = work.K, &C = work.C;
  K.clear();
  C.clear();
  mw.unused.setZero(dofs.n_dofs());
  AddNodeLoads(model, k.mid, s0.t + 0.5 * h, mw.unused, &K);
  AddUserForces(model, k.mid, mw.rates, s0.t + 0.5 * h, nullptr, &K, &C, nullptr);
  AddSpringDampers(model, k.mid, mw.rates, nullptr, &K, &C, nullptr, nullptr, &work.parts.scratch);
  AddJointGeometricStiffness(model, dofs, k.mid, a.node_forces, K, &work.parts.scratch);
  AddTimesColumns(K, 1.0, k.T, triples, mw.triple_of, S);
  for (const Eigen::Triplet<double>& e : C) S.emplace_back(e.row(), e.col(), e.value() / h);
  if (dofs.n_multipliers() > 0) {
    // Loops: d(-G_m^T lambda)/d delta = H_m T, its lambda columns G_m^T, the rows G_n+1.
    mw.loop_mid.clear();
    AddLoopConstraints(model, dofs, k.mid, nullptr, &mw.loop_mid, nullptr, nullptr, kLoopHessian, &mw.mid_data,
                       &work.parts.scratch);
    AddTimesColumns(mw.loop_mid, 1.0, k.T, triples, mw.triple_of, S);
    mw.loop_mid.clear();
    mw.loop_end.clear();
    AddLoopConstraints(model, dofs, k.mid, nullptr, &mw.loop_mid, nullptr, nullptr, kLoopColumns, &mw.mid_data,
                       &work.parts.scratch);
    AddLoopConstraints(model, dofs, s1.config, nullptr, &mw.loop_end, nullptr, nullptr, kLoopRows, &work.pass_data,
                       &work.parts.scratch);
    S.insert(S.end(), mw.loop_end.begin(), mw.loop_end.end());
    S.insert(S.end(), mw.loop_mid.begin(), mw.loop_mid.end());
  }
  return mw.S_build.Build(dofs.n_dofs(), S);
}

}  // namespace

Eigen::VectorXd BodyVelocityOf(const SystemModel& model, const DofMap& dofs, const DynamicState& s, int b) {
  Eigen::VectorXd w;
  BodyVelocityOf(model, dofs, s, b, w);
  return w;
}

void BodyVelocityOf(const SystemModel& model, const DofMap& dofs, const DynamicState& s, int b, Eigen::VectorXd& w) {
  if (s.node_w.empty()) {
    GatherBody(model, dofs, s.config, b, s.W, w);
    return;
  }
  const SuperelementBody& body = model.bodies[b];
  w.resize(body.n_coordinates());
  for (int a = 0; a < body.n_nodes(); ++a) w.segment<6>(6 * a) = s.node_w[size_t(model.body_nodes[b][a])];
  w.tail(body.n_modes()) = s.W.segment(dofs.mode_dof(b), body.n_modes());
}

namespace {

// What a step needs before its first iteration: the model's rotation triples and bodies with a
// free node (once per model), and each body's data, momentum and centre of mass at the step's
// start.
void StartMidpointStep(const SystemModel& model, const DofMap& dofs, const DynamicState& state, BodyWorkspace& work,
                       BodyThreads* threads) {
  work.Weights(model, dofs);
  const std::vector<RotationNode>& triples = work.rotation_triples;
  MidpointWorkspace& mw = work.midpoint;
  if (mw.triple_of.size() != size_t(dofs.n_dofs())) {
    // What depends on the model alone.
    TripleOf(dofs, triples, mw.triple_of);
    mw.L2 = std::pow(ModelSize(model), 2);
    // Bodies with a free node (6 own coordinates) keep the momentum-conserving source terms.
    mw.free_node.assign(model.bodies.size(), 0);
    mw.closes.assign(model.bodies.size(), 0);
    for (size_t b = 0; b < model.bodies.size(); ++b) {
      for (int node : model.body_nodes[b]) mw.free_node[b] |= dofs.free(node);
      mw.closes[b] = ClosesEnergy(model, dofs, int(b));
    }
    FindFreeSystems(model, dofs, mw);
    mw.k.screw_mid.assign(size_t(model.n_nodes()), 0);
    for (size_t b = 0; b < model.bodies.size(); ++b) {
      for (int node : model.body_nodes[b]) mw.k.screw_mid[size_t(node)] |= mw.closes[b];
    }
  }
  // Momenta and centres of mass at the start of the step.
  const int n_bodies = int(model.bodies.size());
  mw.bodies.resize(size_t(n_bodies));
  ForEachBody(threads, n_bodies, [&](int b) {
    const SuperelementBody& body = model.bodies[b];
    MidpointBody& m = mw.bodies[size_t(b)];
    BodyConfigurationOf(model, state.config, b, m.d0.c);
    Evaluate(body, m.d0.c, state.config.frames[b], m.d0);
    BodyVelocityOf(model, dofs, state, b, m.w0);
    m.p0.resize(body.n_coordinates());
    if (body.has_exact_inertia()) {
      m.p0 = MassTimes(body, m.d0, m.w0);
    } else {
      m.p0.noalias() = MapsOf(body, m.d0).Mg * m.w0;
    }
    m.com0 = CenterOfMass(body, m.d0.q, state.config.frames[b]);
    if (mw.closes[size_t(b)]) {
      m.E0 = KineticEnergy(body, m.d0, m.w0) + ElasticEnergy(body, m.d0);
      m.Q0 = LocalForce(body, m.d0);
    }
  });
}

}  // namespace

const Assembly& MidpointResidual(const SystemModel& model, const DofMap& dofs, const DynamicState& s0, double h,
                                 DynamicState& s1, BodyWorkspace& work) {
  StartMidpointStep(model, dofs, s0, work, nullptr);
  for (MidpointBody& m : work.midpoint.bodies) m.dc_fresh = false;  // no step to keep it from
  Midpoint(model, dofs, work.rotation_triples, s0, h, s1, work.midpoint.k);
  AssembleMidpoint(model, dofs, s0, h, s1, work, nullptr, work.assembly);
  return work.assembly;
}

const SystemMatrix& MidpointIterationMatrix(const SystemModel& model, const DofMap& dofs, const DynamicState& s0,
                                            double h, DynamicState& s1, BodyWorkspace& work) {
  MidpointResidual(model, dofs, s0, h, s1, work);
  return MidpointMatrix(model, dofs, s0, h, s1, work, nullptr, work.assembly);
}

StepOutcome MidpointStep(const SystemModel& model, const DofMap& dofs, const DynamicOptions& options,
                         const DynamicState& state, double h, double t_new, IterationMatrix& matrix,
                         BodyThreads& threads, BodyWorkspace& work, DynamicState& next) {
  next = state;  // storage reused: `next` is the caller's, of the same sizes after the first step
  StartMidpointStep(model, dofs, state, work, &threads);
  const Eigen::VectorXd& weights = work.Weights(model, dofs);
  const std::vector<RotationNode>& triples = work.rotation_triples;
  MidpointWorkspace& mw = work.midpoint;
  MidpointKinematics& k = mw.k;
  // Predictor: the configuration reached with the current velocity and acceleration.
  work.dq = h * state.W + 0.5 * h * h * state.Wdot;
  work.inertia_factor = 2.0 / (h * h);  // S_b = K / 2 + C / h + 2 M / h^2
  ApplyIncrement(model, dofs, work.dq, next.config);
  ApplyPrescribed(model, dofs, t_new, next.config, &next.W, &next.Wdot, &work.parts.scratch);
  StepOutcome out;
  const double tolerance = std::max(options.tolerance, kRoundOffTolerance);
  DivergenceTest divergence;
  double last_norm = 0.0;
  int stalled = 0;
  const int n_lambda = dofs.n_multipliers();
  Assembly& a = work.assembly;
  // The energy closures' derivatives go into the next step if this one converges in < 4 iterations.
  ClosureKeeping keeping{mw};
  matrix.BeginStep();
  for (; out.iterations < options.max_iterations; ++out.iterations) {
    Midpoint(model, dofs, triples, state, h, next, k);
    AssembleMidpoint(model, dofs, state, h, next, work, &threads, a);
    if (!a.ok || !a.residual.allFinite()) return out;
    if (n_lambda > 0) {
      // The loop equations at the end of the step: residual rows -g(q_n+1).
      mw.end.setZero(dofs.n_dofs());
      AddLoopConstraints(model, dofs, next.config, &mw.end, nullptr, nullptr, nullptr, kLoopAll, &work.pass_data,
                         &work.parts.scratch);
      a.residual.tail(n_lambda) = mw.end.tail(n_lambda);
    }
    const double r_norm = FreeNorm(dofs, a.residual, weights);
    // Converged, after at least one correction: the residual below the tolerance relative to the
    // forces on each unknown, or at the round-off of the positions (RoundOffForce, an estimate),
    // or within 10x of it after three corrections in a row that did not contract it fourfold (a
    // step of the spinning bar stalled at 2.9x it and was cut). What the leftover would have
    // taken from a free system's momenta KeepMomenta gives back, so nothing is gained by going on
    // at the floor (it cost the spinning bar 0.7 iterations per step).
    stalled = out.iterations > 0 && r_norm > 0.25 * last_norm ? stalled + 1 : 0;
    const bool small = ScaledFreeNorm(dofs, a.residual, weights, a.dof_scale) <= tolerance || r_norm <= a.roundoff ||
                       (stalled >= 3 && r_norm <= 10.0 * a.roundoff);
    if (small && out.iterations > 0 &&
        LoopsClosed(model, next.config, tolerance, &work.pass_data, &work.parts.scratch)) {
      out.converged = true;
      keeping.keep = out.iterations < 4;
      next.t = t_new;
      KeepMomenta(model, dofs, h, a.residual, work, next);
      // a: the mean acceleration over the step (t_n+1/2); Wdot: extrapolated to t_n+1 from
      // the last two means (the predictor's acceleration; also what the output reports).
      next.a = (next.W - state.W) / h;
      if (state.h_last > 0 && h != state.h_last) {
        // Steps of different length: the means sit at t_n - h_last / 2 and t_n + h / 2.
        next.Wdot = next.a + (h / (h + state.h_last)) * (next.a - state.a);
      } else {
        next.Wdot = 1.5 * next.a - 0.5 * state.a;
      }
      next.node_w = k.node_w1;
      next.external_work += StepExternalWork(model, dofs, state.t + 0.5 * h, mw);
      next.f_ext = a.f_ext;
      DriveForces(dofs, a.residual, next.f_drive);
      next.drive_work += next.f_drive.dot(k.delta);
      // The passes hold each body's data and velocities at the end of the step (the measures').
      out.passes_kept = true;
      return out;
    }
    // The energy closures' derivatives (EnergyClosureGradient) computed anew where the last
    // correction contracted the residual less than tenfold.
    if (out.iterations > 0 && r_norm > 0.1 * last_norm) {
      for (MidpointBody& m : mw.bodies) m.dc_fresh = false;
    }
    last_norm = r_norm;
    if (divergence.Diverged(r_norm, !model.has_constraints() || LoopsClosed(model, next.config, tolerance,
                                                                            &work.pass_data, &work.parts.scratch))) {
      return out;
    }
    // Newton's increment at n+1, with the iteration matrix built only when it is factored.
    const SystemMatrix* built = nullptr;
    const auto S = [&]() -> const SystemMatrix& {
      if (!built) built = &MidpointMatrix(model, dofs, state, h, next, work, &threads, a);
      return *built;
    };
    Eigen::VectorXd& delta = work.delta;
    if (!matrix.Increment(dofs, options, h, r_norm, S, a.residual, delta, out.singular_matrix)) return out;
    ApplyIncrement(model, dofs, delta, next.config);
  }
  return out;
}

}  // namespace femb::dynamic_internal
