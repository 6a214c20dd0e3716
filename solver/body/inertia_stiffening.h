// Geometric stiffening of a superelement body by its rigid-body inertia loads: the load factors
// of the floating frame's motion that scale the file's inertia load cases' stiffness.
#pragma once

#include "solver/body/body_model.h"

namespace femb {

/// Stiffening from rigid-body inertia loads (Wallrapp's standard input data, the SID
/// of Simpack; Cardona 2000 for the superelement setting). The reducer stored
/// K_sigma,k = Phi^T G(sigma_k) Phi for the stress sigma_k of the k-th unit inertia field with
/// the interfaces held; the body's local stiffness is K + sum_k a_k K_sigma,k with a_k the
/// floating frame's current values, in frame axes:
///   a_0..2  = R_j^T (xddot_j - g)          (frame origin acceleration, gravity: d'Alembert)
///   a_3..5  = alpha                        (angular acceleration)
///   a_6..11 = w_x^2, w_y^2, w_z^2, w_x w_y, w_x w_z, w_y w_z   (omega x (omega x r) field)
/// The frame's velocity [v_j; omega] = Z Rbar^T w (thesis 3.17); its acceleration from the
/// nodes' accelerations with the centrifugal part of a rigid motion taken out, which Z maps
/// exactly (Z Phi_rig = 1): for a rigid motion R_j^T xddot_k = a_j + alpha x r_k + omega x (omega x r_k)
/// and R_j^T omegadot_k = alpha, so [a_j; alpha] = Z (Rbar^T wdot - c(omega)),
/// c_k = omega x (omega x r_k) on node k's translation rows. d_w and d_wdot are exact at fixed
/// configuration (the configuration dependence of R_j and Z is left out of the tangent).
/// Into `out` (its storage reused).
void InertiaLoads(const SuperelementBody& body, BodyData& d, const BodyVelocity& w, const BodyVelocity& wdot,
                  const Eigen::Vector3d& gravity, InertiaLoadFactors& out);

/// The elastic force f (and with `tangent` its derivative, ElasticForce) stiffened by the inertia
/// loads of the frame's velocity w, acceleration wdot and the gravity field g, whose load factors
/// go into `load`; a body without inertia stiffening gets K q alone and zero factors. Statics
/// (w = wdot = 0, the ramped gravity), generalized-alpha (the iterate's motion) and the midpoint
/// scheme (the step's mean motion at q_m) all take their elastic force from here.
void StiffenedElasticForce(const SuperelementBody& body, BodyData& d, const BodyVelocity& w, const BodyVelocity& wdot,
                           const Eigen::Vector3d& g, InertiaLoadFactors& load, Eigen::VectorXd& f,
                           Eigen::MatrixXd* tangent = nullptr);

// K_sigma,k q_loc for the 12 load cases (n x 12), kept in d.
const Eigen::MatrixXd& SigmaProducts(const SuperelementBody& body, BodyData& d);

}  // namespace femb
