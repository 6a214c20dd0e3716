// The midpoint scheme's energy closure of a flexible body (MidpointWorkspace::closes): its
// inertia force and its elastic force at the mid configuration do over the step a work that
// differs from the change of its kinetic plus elastic energy by O(h^3) (its local coordinates are
// nonlinear in the nodes', and the exact inertia's mass depends on them), which leaves the energy
// of a free flexible body a bounded second-order error. The closure adds to the elastic force the
// mismatch along one direction, as Gonzalez's discrete gradient does (J. Nonlinear Sci. 6, 1996),
// so that the body's forces do exactly the work its energy changes by; the direction is a local
// force through the mid configuration's map, Rbar_m B_m^T W v with v = B_m Rbar_m^T u the local
// image of the body's step u, so it has no resultant and no moment about the origin at q_m: the
// momenta stay exact. Newton's matrix takes the closure's derivative by differences
// (EnergyClosureGradient).
#include <Eigen/Dense>
#include <cmath>

#include "solver/analysis/dynamic_step.h"
#include "solver/body/body_blocks.h"
#include "solver/body/superelement_body.h"
#include "solver/rotation.h"

namespace femb::dynamic_internal {

bool ClosesEnergy(const SystemModel& model, const DofMap& dofs, int b) {
  const SuperelementBody& body = model.bodies[b];
  // A body on one node needs none: its local coordinates are its modal coordinates alone.
  if (body.kind() == BodyKind::kRigid || body.n_nodes() < 2) return false;
  const SuperelementOptions& o = body.options();
  if (body.has_inertia_stiffening() || o.approximated || !o.quadratic_velocity_terms || body.n_constraints() > 0) {
    return false;
  }
  for (int node : model.body_nodes[b]) {
    if (!dofs.free(node) || dofs.node_count(node) != 6) return false;
    for (int j = 0; j < 6; ++j)
      if (dofs.prescribed(dofs.node_first(node) + j)) return false;
  }
  return true;
}

void ScrewMidShift(const Eigen::Vector3d& dpi, const Eigen::Vector3d& dx, const Eigen::Matrix3d& Jinv,
                   Eigen::Ref<Eigen::Vector3d> half, Eigen::Matrix3d& T_translation, Eigen::Matrix3d& T_coupling) {
  // On the geodesic midpoint x_m a node's translation step is Delta_x = 2 sin(phi / 2) n x x_m +
  // t, its rotation step Delta_pi = phi n: a rigid step of the body works (phi - 2 sin(phi / 2)) n
  // . sum_k M_k against node moments M_k. At x* = x_m + c(phi) Delta_pi x Delta_x, c = (1 / (2
  // sin(phi / 2)) - 1 / phi) / phi, Delta_x = Delta_pi x x* + t' with t' the same for every node a
  // rigid step moves alike, so the step is a rigid motion at q_m and forces without moment there
  // do no work along it.
  const double phi = dpi.norm();
  const double c = phi > 1e-3 ? (0.5 / std::sin(0.5 * phi) - 1.0 / phi) / phi : 1.0 / 24 + 7.0 * phi * phi / 5760;
  half += c * dpi.cross(dx);
  // The shift's change: c Delta_pi~ per end translation, -c Delta_x~ J_l^-1(Delta_pi) per end
  // rotation (c's own change left out).
  T_translation += c * Skew<double>(dpi);
  T_coupling -= c * Skew<double>(dx) * Jinv;
}

void AveragedElasticForce(const SuperelementBody& body, BodyData& d1, MidpointBody& m, Eigen::VectorXd& f_int) {
  // The local force of the two ends' strains, (Q(q_n) + Q(q_n+1)) / 2, through the map at q_m:
  // the local coordinates at q_m see the moved mid positions (of order (omega h)^2 / 24 of the
  // body's size), which the ends do not. Kept as the mid data's local force, so that the
  // tangent's geometric terms (MidpointMatrix) take it too.
  BodyData::LocalForceOf& kept = m.dm.local_force;
  kept.Q = m.Q0;
  kept.Q += LocalForce(body, d1);
  kept.Q *= 0.5;
  kept.a.setZero();
  kept.valid = true;
  ElasticForce(body, m.dm, &f_int, nullptr);
}

void AveragedElasticTangent(const SuperelementBody& body, BodyData& d1, MidpointBody& m, Eigen::MatrixXd& K_mid,
                            Eigen::MatrixXd& K_end) {
  // K_mid (the tangent at q_m with the averaged force) keeps its geometric terms, which move with
  // the mid configuration; its first term Rbar_m B_m^T K B_m Rbar_m^T becomes the end strain's own,
  // d (B_m^T Q(q_n+1) / 2) = B_m^T K(q_n+1) B_n+1 / 2 (frames turned on each side), into K_end.
  const int blocks = 2 * body.n_nodes();
  LocalTangent(body, m.dm, nullptr, m.Kq);
  m.KB.noalias() = m.Kq * m.dm.kin.B;
  K_end.noalias() = m.dm.kin.B.transpose() * m.KB;
  body_blocks::TurnNodeBlocks(K_end, blocks, m.dm.frame.R);
  K_mid -= K_end;
  LocalTangent(body, d1, nullptr, m.Kq);
  m.KB.noalias() = m.Kq * d1.kin.B;
  K_end.noalias() = 0.5 * m.dm.kin.B.transpose() * m.KB;
  body_blocks::TurnRowBlocks(K_end, blocks, [&](int) { return m.dm.frame.R; });
  const Eigen::Matrix3d Rt = d1.frame.R.transpose();
  body_blocks::TurnColBlocks(K_end, blocks, [&](int) { return Rt; });
}

void CloseEnergy(const SuperelementBody& body, double h, BodyData& d1, const Eigen::VectorXd& w1, MidpointBody& m,
                 Eigen::VectorXd& f_int) {
  const int blocks = 2 * body.n_nodes();
  m.F += f_int;
  const double E1 = KineticEnergy(body, d1, w1) + ElasticEnergy(body, d1);
  const double work = h * m.F.dot(m.wm);
  const double mismatch = (E1 - m.E0) - work;
  m.mismatch = mismatch;
  // v = B_m Rbar_m^T u, weighted by the body's local mass diagonal.
  const Eigen::Matrix3d& R = m.dm.frame.R;
  Eigen::VectorXd& u = m.u_local;
  u = h * m.wm;
  for (int a = 0; a < blocks; ++a) u.segment<3>(3 * a) = R.transpose() * u.segment<3>(3 * a);
  m.v.noalias() = m.dm.kin.B * u;
  m.Wv = m.v.cwiseProduct(body.M().diagonal().cwiseAbs());
  const double norm = m.Wv.dot(m.v);
  m.closure_on = norm > 0;
  if (!m.closure_on) return;
  m.closure.noalias() = m.dm.kin.B.transpose() * m.Wv;
  m.closure /= norm;
  for (int a = 0; a < blocks; ++a) m.closure.segment<3>(3 * a) = R * m.closure.segment<3>(3 * a);
  f_int += m.closure * mismatch;
}

void EnergyClosureGradient(const SystemModel& model, const DofMap& dofs, const DynamicState& s0, double h,
                           const DynamicState& s1, int b, BodyWorkspace& work) {
  MidpointWorkspace& mw = work.midpoint;
  if (!mw.closure_scratch) mw.closure_scratch = std::make_shared<BodyWorkspace>();
  BodyWorkspace& sw = *mw.closure_scratch;
  const size_t n_bodies = model.bodies.size();
  // The scratch workspace: the model's constants and body b's data at the step's start.
  sw.inertia_factor = work.inertia_factor;
  sw.rotation_triples = work.rotation_triples;
  MidpointWorkspace& smw = sw.midpoint;
  smw.L2 = mw.L2;
  smw.free_node = mw.free_node;
  smw.closes = mw.closes;
  smw.k.screw_mid = mw.k.screw_mid;
  smw.gravity_work.assign(n_bodies, 0.0);
  smw.bodies.resize(n_bodies);
  sw.passes.resize(n_bodies);
  sw.terms.resize(n_bodies);
  MidpointBody& m = mw.bodies[size_t(b)];
  MidpointBody& sm = smw.bodies[size_t(b)];
  sm.w0 = m.w0;
  sm.p0 = m.p0;
  sm.E0 = m.E0;
  sm.Q0 = m.Q0;
  sm.com0 = m.com0;
  const SuperelementBody& body = model.bodies[b];
  const int n = body.n_coordinates();
  const double L = std::sqrt(mw.L2), modal = L * std::sqrt(std::max(body.mass(), 1e-300));
  DynamicState& s = mw.closure_state;
  s = s1;
  Eigen::VectorXd& d = sw.delta;
  d.setZero(dofs.n_dofs());
  m.dc.resize(n, n);
  m.base = m.closure * m.mismatch;
  for (int j = 0; j < n; ++j) {
    const int a = j / 6;
    const int col = j < 6 * body.n_nodes() ? dofs.node_first(model.body_nodes[b][size_t(a)]) + j % 6
                                           : dofs.mode_dof(b) + j - 6 * body.n_nodes();
    const double eps = 1e-8 * (j >= 6 * body.n_nodes() ? modal : (j % 6 < 3 ? L : 1.0));
    // One-sided: the residual pass's own closure at s1 is the base.
    s.config = s1.config;
    d[col] = eps;
    ApplyIncrement(model, dofs, d, s.config);
    d[col] = 0.0;
    Midpoint(model, dofs, sw.rotation_triples, s0, h, s, smw.k);
    MidpointBodyTerms(model, dofs, s0, h, s, b, sw);
    m.dc.col(j) = -m.base;
    if (sm.closure_on) m.dc.col(j).noalias() += sm.closure * sm.mismatch;
    m.dc.col(j) /= eps;
  }
}
}  // namespace femb::dynamic_internal
