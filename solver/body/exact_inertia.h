// The exact inertia of a superelement body: the kinetic energy of the reduced field in the
// floating frame from the file's inertia invariants.
//
// Exact inertia. The reduced field in frame axes is X + Phi q_loc, its velocity
// v_j + Omega x (X + Phi q_loc) + Phi qdot_loc, so with y = Phi_rig0 xi + qdot_loc,
// xi = (v_j, Omega) = Z Rbar^T w and qdot_loc = B Rbar^T w (thesis 3.17), the kinetic energy of
// the full model's mass is (Wallrapp's floating frame of reference form, the invariants
// Gamma_a, Xi_ab of formats/superelement.h)
//   T = y^T M y / 2 + y^T Gamma(Omega) q + q^T Xi(Omega) q / 2,
//   Gamma(Omega) = sum_a Omega_a Gamma_a,  Xi(Omega) = sum_ab Omega_a Omega_b Xi_ab.
// The thesis' T = (Rbar^T w)^T M (Rbar^T w) / 2 differs from it at the order of q Omega: it
// turns the interface displacements with the frame but interpolates them with the modes
// (Omega x u_k at the nodes in place of Omega x (Phi q) in the body; the internal modes not at
// all), and it takes the interface angular velocities for the rates of the local rotations
// (J_l(theta) thetadot for thetadot); for a rotating cantilever that gave in-plane softening
// -1.34 Omega^2 instead of -Omega^2 and a flapwise softening -0.3 Omega^2 that has no physical
// cause (a gyroscopic coupling of tip torsion and tip slope through the momentum of the
// rotating body). The equations of motion: Kirchhoff's for the frame,
//   f_xi = d/dt dT/dxi + [Omega x pi_v; Omega x pi_Omega + v x pi_v],
// Lagrange's for the local coordinates, f_q = d/dt dT/dqdot - dT/dq, and by virtual work
// (delta xi = Z Rbar^T dq, delta q_loc = B Rbar^T dq) f_in = Rbar (Z^T f_xi + B^T f_q). The
// accelerations: differentiating Rbar^T w = Phi_rig xi + D^-1 qdot_loc (with Phi_CB qdot_loc
// = 0) gives xidot = Z r, qddot_loc = B r, r = Rbar^T wdot - c, c = Omega^ Rbar^T w
// + [Omega x udot_k; (d/dt J_l(theta_k)) thetadot_k] on the node rows. T = w^T M_g w / 2 with
// M_g = Rbar (Y^T M Y + Y^T H Z_r + Z_r^T H^T Y + Z_r^T X_q Z_r) Rbar^T, Y = Phi_rig0 Z + B,
// Z_r the rotation rows of Z, H = [Gamma_a q], (X_q)_ab = q^T Xi_ab q.
#pragma once

#include "solver/body/body_model.h"

namespace femb {

// M_g of the exact inertia, computed once per data (BodyData::exact_mass).
const Eigen::MatrixXd& ExactMass(const SuperelementBody& body, BodyData& d);

// With `f_acc`, also the part linear in wdot alone (M_g wdot) from the same products.
void ExactInertiaForce(const SuperelementBody& body, BodyData& d, const BodyVelocity& w, const BodyVelocity& wdot,
                       Eigen::VectorXd& f, Eigen::VectorXd* f_acc);

// d f_in / d w of the exact inertia force (forward mode, exact).
void ExactGyroscopic(const SuperelementBody& body, BodyData& d, const BodyVelocity& w, Eigen::MatrixXd& G);

Eigen::MatrixXd ExactInertiaConfigurationTangent(const SuperelementBody& body, BodyData& d, const BodyVelocity& w,
                                                 const BodyVelocity& wdot);

void ExactMassTimesTurned(const SuperelementBody& body, BodyData& data, const Eigen::VectorXd& r, Eigen::VectorXd& out);

// c = Rbar B^T g, g = dT/dq_loc at fixed Rbar^T w (MomentumSource(BodyData&, ...)), into out.
void ExactMomentumSource(const SuperelementBody& body, BodyData& data, const BodyVelocity& w, Eigen::VectorXd& out);

// The kernels' shared steps.
// Exact inertia (has_exact_inertia): per-configuration data (into `d`, its storage reused), the
// force, the mass matrix M_g.
void Exact(const SuperelementBody& body, const Eigen::VectorXd& q, const BodyKinematics& kin, ExactInertiaData& d);
// M Y and H^T Y of d.exact, made on the first call.
const ExactInertiaData& ExactProducts(const SuperelementBody& body, BodyData& d);
// r -= c(Omega, Rbar^T w, qdot_loc) at local coordinates q (LocalRates, ExactInertiaForce).
void SubtractRateTerms(const SuperelementBody& body, const Eigen::VectorXd& q, const Eigen::Vector3d& Om,
                       const Eigen::VectorXd& Rw, const Eigen::VectorXd& qd, Eigen::VectorXd& r);
// [Gamma_0 v, Gamma_1 v, Gamma_2 v] (n x 3) from the stack, into `out` (its storage reused).
void GammaColumns(const SuperelementBody& body, const Eigen::VectorXd& v, Eigen::MatrixXd& out);

}  // namespace femb
