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
//                spurious axial force in a 1 m tube at 20 rad/s and 200 steps per turn.
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
// is conserved too; for flexible bodies the energy error is second order and small (free
// spinning tube: 6e-6 against generalized-alpha's 2e-3). No numerical damping.
//
// Chains of joints (nodes that are functions of other nodes' coordinates) get three more
// pieces, so that a chain or loop of rigid bodies keeps its energy exactly too (issue 15):
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


// The step's increment Delta of the coordinates (spatial rotation vectors log(R_n+1 R_n^T) on
// the rotation triples), the end velocities it implies, the mid configuration, and the first-
// order maps of the end coordinates' increments (delta, as Newton applies them at n+1) to the
// mid configuration and to the end velocities.
struct MidpointKinematics {
  Eigen::VectorXd delta;  // Delta
  SystemState mid;        // q_m
  SystemMatrix T;         // d q_m / d delta: 1/2 off the rotation nodes
  SystemMatrix V;         // d W_n+1 / d delta: 2/h off the rotation nodes
  std::vector<Eigen::Matrix<double, 6, 1>> node_w1;  // every node's velocity at n+1 (EndNodeVelocity)
};

// The velocity at n+1 of a node that hangs on joints, from its motion over the step and its
// velocity at n: xdot_n+1 = 2 (x_n+1 - x_n) / h - xdot_n and, as for a rotation node (Simo & Wong),
// omega_n+1 = R_n+1 (2 Omega_m - R_n^T omega_n), Omega_m = R_n^T log(R_n+1 R_n^T) / h. This is not
// J(q_n+1) W_n+1 (the two differ by O(h^2), without accumulating), but it is what the bodies'
// momentum balance pairs with their kinetic energy: with J(q) W at both ends a chain of joints
// drifts as O(h^2) (a rigid four-bar under gravity 1.5e-5 of its energy over 10 s at h = 1 ms).
// The scheme carries these node velocities from step to step (DynamicState::node_w), as the
// discrete null space method carries redundant velocities (Betsch & Leyendecker, Int. J. Numer.
// Meth. Engng 67, 2006). Nodes with their own coordinates (free nodes, supports) keep W's.
Eigen::Matrix<double, 6, 1> EndNodeVelocity(const Eigen::Vector3d& x0, const Eigen::Matrix3d& R0,
                                            const Eigen::Vector3d& x1, const Eigen::Matrix3d& R1,
                                            const Eigen::Matrix<double, 6, 1>& w0, double h) {
  const Eigen::Vector3d Omega_m = R0.transpose() * LogSO3(R1 * R0.transpose()) / h;
  Eigen::Matrix<double, 6, 1> w1;
  w1 << 2.0 * (x1 - x0) / h - w0.head<3>(), R1 * (2.0 * Omega_m - R0.transpose() * w0.tail<3>());
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

MidpointKinematics Midpoint(const SystemModel& model, const DofMap& dofs, const std::vector<RotationNode>& nodes,
                            const DynamicState& s0, double h, DynamicState& s1) {
  MidpointKinematics k;
  const int n = dofs.n_dofs();
  k.delta = Eigen::VectorXd::Zero(n);
  for (int node = 0; node < model.n_nodes(); ++node) {
    if (dofs.node_count(node) > 0) {
      k.delta.segment(dofs.node_first(node), dofs.node_count(node)) = s1.config.z[node] - s0.config.z[node];
    }
  }
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    k.delta.segment(dofs.mode_dof(int(b)), model.bodies[b].n_modes()) = s1.config.eta[b] - s0.config.eta[b];
  }
  // Every other coordinate: z_n+1 - z_n = h (W_n + W_n+1) / 2, z_m = z_n + Delta / 2.
  Eigen::VectorXd W1 = 2.0 / h * k.delta - s0.W;
  Eigen::VectorXd half = 0.5 * k.delta;
  std::vector<bool> in_block(n, false);
  Triplets T, V;
  auto add_block = [](Triplets& t, int row, int col, const Eigen::Matrix3d& block) {
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) t.emplace_back(row + i, col + j, block(i, j));
    }
  };
  for (const RotationNode& r : nodes) {
    const Eigen::Matrix3d& R0 = s0.config.R[r.node];
    const Eigen::Matrix3d& R1 = s1.config.R[r.node];
    const Eigen::Vector3d dpi = LogSO3(R1 * R0.transpose());
    k.delta.segment<3>(r.rotation) = dpi;
    half.segment<3>(r.rotation) = 0.5 * dpi;
    const Eigen::Vector3d Omega_m = R0.transpose() * dpi / h;
    const Eigen::Vector3d omega1 = R1 * (2.0 * Omega_m - R0.transpose() * s0.W.segment<3>(r.rotation));
    W1.segment<3>(r.rotation) = omega1;
    for (int i = 0; i < 3; ++i) in_block[r.rotation + i] = true;
    // An end increment delta (R_n+1 <- exp(delta~) R_n+1) changes Delta_pi by J_l^-1(Delta_pi)
    // delta: the mid rotation exp(Delta_pi~ / 2) R_n by A delta / 2, A = J_l(Delta_pi / 2)
    // J_l^-1(Delta_pi), and omega_n+1 by [2/h R_n+1 R_n^T J_l^-1(Delta_pi) - omega_n+1~] delta.
    const Eigen::Matrix3d Jinv = LeftJacobianInverse<double>(dpi);
    const Eigen::Matrix3d A = LeftJacobianInverse<double>(Eigen::Vector3d(0.5 * dpi)).inverse() * Jinv;
    add_block(T, r.rotation, r.rotation, 0.5 * A);
    add_block(V, r.rotation, r.rotation, 2.0 / h * R1 * R0.transpose() * Jinv - Skew<double>(omega1));
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
    half.segment<3>(r.translation) = R0 * (J_half * (0.5 * h * V_m));
    for (int i = 0; i < 3; ++i) in_block[r.translation + i] = true;
    add_block(T, r.translation, r.translation, 0.5 * A);
    add_block(T, r.translation, r.rotation, Skew<double>(dx) / 8.0);
    // xdot_n+1: 2/h R_n+1 J_l^-1(h Omega_m) R_n^T per end translation; per end rotation
    // -xdot_n+1~ (turning R_n+1) + R_n+1 V_m~ R_n^T (through Omega_m), to first order.
    add_block(V, r.translation, r.translation, 2.0 / h * R1 * Jinv_step * R0.transpose());
    add_block(V, r.translation, r.rotation, -Skew<double>(xdot1) + R1 * Skew<double>(V_m) * R0.transpose());
  }
  for (int j = 0; j < n; ++j) {
    if (in_block[j]) continue;
    T.emplace_back(j, j, 0.5);
    V.emplace_back(j, j, 2.0 / h);
  }
  k.T = ToMatrix(n, T);
  k.V = ToMatrix(n, V);
  // End velocities from the kinematics (prescribed coordinates keep their given rates).
  for (int j : dofs.solved()) s1.W[j] = W1[j];
  // Node velocities at n+1 (after W_n+1: free nodes and supports take theirs from it).
  k.node_w1.resize(size_t(model.n_nodes()));
  for (int node = 0; node < model.n_nodes(); ++node) {
    k.node_w1[size_t(node)] = dofs.joint_of(node) < 0
                                  ? NodeMotion(s1.config, node, s1.W)
                                  : EndNodeVelocity(s0.config.x[node], s0.config.R[node], s1.config.x[node],
                                                    s1.config.R[node], NodeVelocity(s0, node), h);
  }
  k.mid = s0.config;
  ApplyIncrement(model, dofs, half, k.mid);
  return k;
}

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
void AddDiscreteGradientCorrection(const SystemModel& model, const DofMap& dofs, const SystemState& c0,
                                   const SystemState& c1, const MidpointKinematics& k, double L2, Assembly& out) {
  if (model.joints.empty()) return;
  const int n = dofs.first_multiplier();
  Eigen::VectorXd D = Eigen::VectorXd::Zero(n);
  double gap_work = 0.0;
  for (int node = 0; node < model.n_nodes(); ++node) {
    if (dofs.joint_of(node) < 0) continue;
    Eigen::Matrix<double, 6, 1> gap = NodeStep(c0, c1, node);
    for (const auto& [col, vec] : k.mid.J[node]) {
      gap -= vec * k.delta[col];
      D[col] += vec.head<3>().squaredNorm() + L2 * vec.tail<3>().squaredNorm();
    }
    gap_work += gap.dot(out.node_forces.f[node]);
  }
  const Eigen::VectorXd Dd = D.cwiseProduct(k.delta.head(n));
  const double norm = Dd.dot(k.delta.head(n));
  if (!(norm > 0)) return;
  out.residual.head(n) += Dd * (gap_work / norm);
}

// Residual (applied minus inertia and internal forces, over the coordinates) of the midpoint
// balance and the matrices at the mid configuration.
Assembly AssembleMidpoint(const SystemModel& model, const DofMap& dofs, const DynamicState& s0,
                          const std::vector<Eigen::VectorXd>& p0, double h, MidpointKinematics& k, DynamicState& s1,
                          double& f_ext_work, BodyThreads* threads = nullptr) {
  AssemblyParts parts;
  Assembly out = StartAssembly(model, dofs, parts);
  // Each body into its slot (on the threads), then added in body order.
  const int n_bodies = int(model.bodies.size());
  std::vector<BodyTerms> terms(static_cast<size_t>(n_bodies));
  const double L2 = std::pow(std::max(BoundingDiagonal(model.node_x0), 1e-300), 2);
  // Bodies with a free node (6 own coordinates) keep the momentum-conserving source terms.
  std::vector<char> free_node(static_cast<size_t>(n_bodies), 0);
  for (int b = 0; b < n_bodies; ++b) {
    for (int node : model.body_nodes[b]) free_node[size_t(b)] |= dofs.free(node);
  }
  std::vector<double> gravity_work(static_cast<size_t>(n_bodies), 0.0);
  ForEachBody(threads, n_bodies, [&](int b) {
    const SuperelementBody& body = model.bodies[b];
    BodyTerms& r = terms[size_t(b)];
    const BodyConfiguration c1 = BodyConfigurationOf(model, s1.config, int(b));
    const BodyConfiguration cm = BodyConfigurationOf(model, k.mid, int(b));
    const FrameSolution f1 = body.SolveFrameFrom(c1, s1.config.frames[b]);
    const FrameSolution fm = f1.ok ? body.SolveFrameFrom(cm, s0.config.frames[b]) : FrameSolution{};
    if (!f1.ok || !fm.ok) {
      r.frame_ok = false;
      return;
    }
    s1.config.frames[b] = f1;
    k.mid.frames[b] = fm;
    Eigen::VectorXd w1(body.n_coordinates());
    for (int a = 0; a < body.n_nodes(); ++a) w1.segment<6>(6 * a) = k.node_w1[size_t(model.body_nodes[b][a])];
    w1.tail(body.n_modes()) = s1.W.segment(dofs.mode_dof(int(b)), body.n_modes());
    // Velocity maps at the end and at the mid configuration, shared by the momentum terms.
    const SuperelementBody::Data d1 = body.Evaluate(c1, f1), dm = body.Evaluate(cm, fm);
    const BodyVelocityMaps &maps1 = body.MapsOf(d1), &maps_m = body.MapsOf(dm);
    const Eigen::VectorXd p1 = body.GeneralizedMomentum(maps1, w1);
    // Node motion over the step.
    Eigen::VectorXd wm(body.n_coordinates());
    for (int a = 0; a < body.n_nodes(); ++a) wm.segment<6>(6 * a) = NodeStep(s0.config, s1.config, model.body_nodes[b][a]) / h;
    wm.tail(body.n_modes()) = (s1.config.eta[b] - s0.config.eta[b]) / h;
    Eigen::VectorXd f_in, f_int;
    Eigen::MatrixXd &Kb = r.K, &Mb = r.M, &Cb = r.C;
    // M_g at the end of the step: the 2/h^2 term of the iteration matrix is d p_n+1 / h; at
    // the mid configuration it would be off by O(omega h) and leave a 1/h error.
    Mb = maps1.Mg;
    const Eigen::VectorXd w0 = BodyVelocityOf(model, dofs, s0, int(b));
    const Eigen::VectorXd f_acc = Mb * (w1 - w0) / h;
    Cb.setZero(body.n_coordinates(), body.n_coordinates());
    if (body.options().quadratic_velocity_terms) {
      // Source terms with the node motion of each half step, so that their moment matches the
      // change of sum x_k x p_k exactly: x_m is not the mean of x_n and x_n+1.
      if (free_node[size_t(b)]) {
        Eigen::VectorXd w_second = wm, w_first = wm;
        for (int a = 0; a < body.n_nodes(); ++a) {
          const int node = model.body_nodes[b][a];
          w_second.segment<3>(6 * a) = 2.0 * (s1.config.x[node] - k.mid.x[node]) / h;
          w_first.segment<3>(6 * a) = 2.0 * (k.mid.x[node] - s0.config.x[node]) / h;
        }
        f_in = (p1 - p0[b]) / h -
               0.5 * (body.MomentumSource(maps_m, w_second, p1) + body.MomentumSource(maps_m, w_first, p0[b]));
      } else {
        // No free node: every node hangs on joints or supports. The source at the step's mean
        // motion and mean momentum does no work for a rigid body, s(wm, p_m) . wm =
        // (wm~ U wm) . M wm = 0 with trapezoidal node velocities, so the energy of a chain of
        // rigid bodies is conserved to Newton's tolerance (four-bar under gravity: 4e-10 over
        // 10 s, against 1.5e-5 with the split source). The price: the moment of this source
        // no longer matches the change of sum x_k x p_k exactly, so a chain whose root floats
        // free keeps its angular momentum to O(h^2) only (a grounded chain has none to keep).
        // Energy is the invariant a mechanism on joints is judged by.
        f_in = (p1 - p0[b]) / h - body.MomentumSource(maps_m, wm, 0.5 * (p0[b] + p1));
      }
      // Iteration matrix: with dp_n+1 = (M_g V + D) delta (V = d W_n+1 / d delta ~ 2/h,
      // D = d p / dq at fixed w) and dw_a ~ delta / h,
      //   d f_in / d delta = [M_g V + D - d_w s(p_mean) - (d_p s) M_g] / h + O(1).
      // All the 1/h terms are needed (and M_g at n+1, V with its O(omega) part): each is
      // O(omega h) of the leading one, and without them Newton contracts only by ~omega h per
      // iteration, or worse on stiff, lightly inertial directions such as a tube's torsion.
      Eigen::MatrixXd d_w, d_p;
      body.MomentumSourceDerivatives(maps_m, wm, 0.5 * (p0[b] + p1), &d_w, &d_p);
      Cb = body.MomentumDerivative(maps1, w1) - d_w - d_p * Mb;
    } else {
      f_in = f_acc;
    }
    body.AddModalDamping(wm, f_in, &Cb);
    if (body.has_inertia_stiffening()) {
      // Inertia stiffening (issue 13) at the mid configuration with the step's mean velocity and
      // acceleration; d wm = delta / h (C / h) and d (w1 - w0) / h = V delta / h (M V / h).
      const InertiaLoadFactors load = body.InertiaLoads(dm, wm, (w1 - w0) / h, model.gravity);
      Eigen::MatrixXd d_load;
      body.ElasticForce(dm, &f_int, &Kb, &load, &d_load);
      Cb += d_load * load.d_w;
      Mb += d_load * load.d_wdot;
    } else {
      body.ElasticForce(dm, &f_int, &Kb);
    }
    Eigen::VectorXd& f_grav = r.f_grav;
    f_grav = Eigen::VectorXd::Zero(body.n_coordinates());
    if (model.gravity.squaredNorm() > 0) {
      f_grav = body.GravityForce(dm, model.gravity);
      // Gravity as a discrete gradient of its potential V = -m g . x_c (Gonzalez): its work over
      // the step's motion u = h wm is exactly V_n - V_n+1, where the force at q_m alone is off
      // by O(h^3) (x_c turns with the frame). The correction lies along D u, D = 1 on node
      // translations and the model's size squared on node rotations.
      const Eigen::VectorXd u = h * wm;
      const double dV = -body.mass() * model.gravity.dot(body.CenterOfMass(c1, f1) -
                                                         body.CenterOfMass(BodyConfigurationOf(model, s0.config, int(b)),
                                                                           s0.config.frames[b]));
      Eigen::VectorXd Du = Eigen::VectorXd::Zero(u.size());
      for (int a = 0; a < body.n_nodes(); ++a) {
        Du.segment<3>(6 * a) = u.segment<3>(6 * a);
        Du.segment<3>(6 * a + 3) = L2 * u.segment<3>(6 * a + 3);
      }
      const double norm = Du.dot(u);
      if (norm > 0) f_grav += Du * ((-dV - f_grav.dot(u)) / norm);
      gravity_work[size_t(b)] = -dV;
    }
    // Scale: each term on its own (for a torque-free body the momentum change and the source
    // cancel; M_g (w_n+1 - w_n) / h is the size of the inertia force).
    r.scale = std::max({body.ForceNorm(f_int), body.ForceNorm(f_in), body.ForceNorm(f_grav), body.force_floor(),
                        body.ForceNorm(f_acc)});
    r.roundoff = body.RoundOffForce(c1);
    r.map = BodyMap(model, dofs, k.mid, int(b));
    r.r_b = f_grav - f_int - f_in;
  });
  if (!AddBodyTerms(model, terms, parts, out)) return out;
  // Closed loops: the constraint forces -G^T lambda_n+1 at the mid configuration (their work
  // over the step, lambda . G(q_m) Delta, is lambda . (g_n+1 - g_n) = 0 up to O(h^3)); the
  // equations themselves hold at the end of the step (MidpointStep).
  k.mid.lambda = s1.config.lambda;
  AddLoopConstraints(model, dofs, k.mid, &out.residual, nullptr, &parts.node_forces);
  // Loads at the mid time and configuration, spring-dampers at the mean rates Delta / h.
  FinishAssembly(model, dofs, k.mid, s0.t + 0.5 * h, k.delta / h, true, parts, out);
  AddDiscreteGradientCorrection(model, dofs, s0.config, s1.config, k, L2, out);
  // The external work of the step, as the forces' discrete gradients do it: gravity's potential
  // change, and the nodal loads (at q_m) times the nodes' motion.
  f_ext_work = 0.0;
  for (double w : gravity_work) f_ext_work += w;
  if (!model.loads.empty()) {
    NodeForces loads = ZeroNodeForces(model);
    Eigen::VectorXd unused = Eigen::VectorXd::Zero(dofs.n_dofs());
    AddNodeLoads(model, k.mid, s0.t + 0.5 * h, unused, nullptr, &loads);
    for (int node = 0; node < model.n_nodes(); ++node) {
      f_ext_work += NodeStep(s0.config, s1.config, node).dot(loads.f[size_t(node)]);
    }
  }
  return out;
}

}  // namespace

Eigen::VectorXd BodyVelocityOf(const SystemModel& model, const DofMap& dofs, const DynamicState& s, int b) {
  if (s.node_w.empty()) return GatherBody(model, dofs, s.config, b, s.W);
  const SuperelementBody& body = model.bodies[b];
  Eigen::VectorXd w(body.n_coordinates());
  for (int a = 0; a < body.n_nodes(); ++a) w.segment<6>(6 * a) = s.node_w[size_t(model.body_nodes[b][a])];
  w.tail(body.n_modes()) = s.W.segment(dofs.mode_dof(b), body.n_modes());
  return w;
}

StepOutcome MidpointStep(const SystemModel& model, const DofMap& dofs, const DynamicOptions& options,
                         const std::vector<RotationNode>& triples, const DynamicState& state, double h, double t_new,
                         IterationMatrix& matrix, BodyThreads& threads, DynamicState& next) {
  next = state;
  // Momenta at the start of the step.
  std::vector<Eigen::VectorXd> p0;
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    const BodyConfiguration c = BodyConfigurationOf(model, state.config, int(b));
    p0.push_back(model.bodies[b].GeneralizedMomentum(model.bodies[b].Maps(c, state.config.frames[b]),
                                                     BodyVelocityOf(model, dofs, state, int(b))));
  }
  // Predictor: the configuration reached with the current velocity and acceleration.
  ApplyIncrement(model, dofs, h * state.W + 0.5 * h * h * state.Wdot, next.config);
  ApplyPrescribed(model, dofs, t_new, next.config, &next.W, &next.Wdot);
  StepOutcome out;
  const double tolerance = std::max(options.tolerance, kRoundOffTolerance);
  const Eigen::VectorXd weights = ResidualWeights(model, dofs);
  DivergenceTest divergence;
  const int n_lambda = dofs.n_multipliers();
  matrix.BeginStep();
  for (; out.iterations < options.max_iterations; ++out.iterations) {
    MidpointKinematics k = Midpoint(model, dofs, triples, state, h, next);
    double work = 0.0;
    Assembly a = AssembleMidpoint(model, dofs, state, p0, h, k, next, work, &threads);
    if (!a.ok || !a.residual.allFinite()) return out;
    if (n_lambda > 0) {
      // The loop equations at the end of the step: residual rows -g(q_n+1).
      Eigen::VectorXd end = Eigen::VectorXd::Zero(dofs.n_dofs());
      AddLoopConstraints(model, dofs, next.config, &end, nullptr, nullptr);
      a.residual.tail(n_lambda) = end.tail(n_lambda);
    }
    const double r_norm = FreeNorm(dofs, a.residual, weights);
    // Converged: the residual below the tolerance relative to the forces on each unknown (or
    // at the round-off of the positions), after at least one correction.
    const bool small = r_norm <= a.roundoff || ScaledFreeNorm(dofs, a.residual, weights, a.dof_scale) <= tolerance;
    if (small && out.iterations > 0 &&
        LoopsClosed(model, next.config, tolerance)) {
      out.converged = true;
      next.t = t_new;
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
      next.external_work += work;
      next.f_ext = a.f_ext;
      next.f_drive = DriveForces(dofs, a.residual);
      next.drive_work += next.f_drive.dot(k.delta);
      return out;
    }
    if (divergence.Diverged(out.iterations, r_norm)) return out;
    // Newton's increment delta at n+1: dW_n+1 = V delta, dq_m = T delta, dw_m ~ delta / h.
    const auto S = [&] {
      SystemMatrix S = a.K * k.T + (1.0 / h) * (a.C + a.M * k.V);
      if (n_lambda == 0) return S;
      // Loops: d(-G_m^T lambda)/d delta = H_m T, its lambda columns G_m^T, the rows G_n+1.
      Triplets at_mid, at_end;
      AddLoopConstraints(model, dofs, k.mid, nullptr, &at_mid, nullptr, nullptr, kLoopHessian);
      S += ToMatrix(dofs.n_dofs(), at_mid) * k.T;
      at_mid.clear();
      AddLoopConstraints(model, dofs, k.mid, nullptr, &at_mid, nullptr, nullptr, kLoopColumns);
      AddLoopConstraints(model, dofs, next.config, nullptr, &at_end, nullptr, nullptr, kLoopRows);
      at_end.insert(at_end.end(), at_mid.begin(), at_mid.end());
      return SystemMatrix(S + ToMatrix(dofs.n_dofs(), at_end));
    };
    Eigen::VectorXd delta;
    if (!matrix.Increment(dofs, options, h, r_norm, S, a.residual, delta, out.singular_matrix)) return out;
    ApplyIncrement(model, dofs, delta, next.config);
  }
  return out;
}


}  // namespace femb::dynamic_internal
