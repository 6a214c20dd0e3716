// The inertia of a superelement body whichever kinetic energy it uses (the exact one when the
// file has the invariants and the option allows, else the corotational one): the inertia force
// and its matrices, the mass, the momenta, the modal damping and the weight.
#pragma once

#include "solver/body/body_model.h"

namespace femb {

/// Inertia force from the corotational kinetic energy T = v^T M v / 2, v = P w (thesis 3.22,
/// 4.9; DESIGN.md "Inertia"), P = blockdiag(R_j^T ... , 1) (option A) or with R_k^T on the
/// angular rows (option B). With G defined by d(P w) = P G dq and Omega_P, Omega_hat the
/// block-diagonal skew matrices of Pdot^T = Omega_P P^T and of the node angular velocities:
///   f_in = M_g wdot + M_g G w + (Omega_P - Omega_hat) p - G^T p,  M_g = P^T M P, p = M_g w.
/// `mass` receives M_g, `gyroscopic` d f_in / d w (exact: f_in is quadratic in w).
/// `f_acc` (optional) receives the part linear in wdot, M_g wdot.
void InertiaForce(const SuperelementBody& body, BodyData& d, const BodyVelocity& w, const BodyVelocity& wdot,
                  Eigen::VectorXd* f_in, Eigen::MatrixXd* mass, Eigen::MatrixXd* gyroscopic,
                  Eigen::VectorXd* f_acc = nullptr);

/// d f_in / dq at fixed (w, wdot): d(M_g wdot)/dq = MomentumDerivative(MapsOf(d), wdot)
/// (exact), plus with `quadratic` the configuration derivative of the quadratic velocity terms
/// by central differences (2n evaluations with the frame re-solved; steps 1e-7 of the body
/// size, 1e-7 rad, 1e-7 of the modal scale). Into `tangent` (its storage reused).
void InertiaConfigurationTangent(const SuperelementBody& body, BodyData& d, const BodyVelocity& w,
                                 const BodyVelocity& wdot, bool quadratic, Eigen::MatrixXd& tangent);

/// Modal damping force 2 zeta omega_i etadot_i on the internal-mode rows and its derivative
/// with respect to w (added to `f` and `C`).
void AddModalDamping(const SuperelementBody& body, const BodyVelocity& w, Eigen::VectorXd& f, Eigen::MatrixXd* C);

/// The mass matrix d^2 T / dw^2 at `d`: the exact one or the corotational M_g (MapsOf).
const Eigen::MatrixXd& Mass(const SuperelementBody& body, BodyData& d);

/// M_g w, into d.scratch.v1 (the exact inertia: without forming M_g).
const Eigen::VectorXd& MassTimes(const SuperelementBody& body, BodyData& d, const BodyVelocity& w);

/// Kinetic energy v^T M v / 2.
double KineticEnergy(const SuperelementBody& body, BodyData& d, const BodyVelocity& w);

/// Linear momentum and angular momentum about the global origin (Noether: sums of the
/// generalized momenta p = M_g w of the nodes).
void Momentum(const SuperelementBody& body, BodyData& d, const BodyVelocity& w, Eigen::Vector3d* linear,
              Eigen::Vector3d* angular);

/// The same from the generalized momentum p = M_g w (MassTimes).
void MomentumFrom(const SuperelementBody& body, BodyData& d, const Eigen::VectorXd& p, Eigen::Vector3d* linear,
                  Eigen::Vector3d* angular);

/// Generalized force of a uniform acceleration field g (gravity): P^T M Phi_rig0 [R_j^T g; 0].
/// Into `f` (its storage reused).
void GravityForce(const SuperelementBody& body, BodyData& d, const Eigen::Vector3d& g, Eigen::VectorXd& f);

/// d GravityForce / dq (n x n): the weight's distribution over the nodes and modes turns with
/// the floating frame. Corotational inertia: GravityForce = M_g wdot_g (wdot_g = g on the node
/// translations), so MomentumDerivative(maps, wdot_g), exact; exact inertia: central
/// differences (steps as in InertiaConfigurationTangent). A pendulum hanging from a pin owes
/// its whole restoring stiffness to it.
Eigen::MatrixXd GravityTangent(const SuperelementBody& body, BodyData& d, const Eigen::Vector3d& g);

}  // namespace femb
