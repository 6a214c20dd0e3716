// The corotational inertia of a superelement body (thesis 3.22, 4.9-4.11; Cardona's options A
// and B): T = v^T M v / 2 of the interface velocities in the frame, its maps and their rates.
#pragma once

#include "solver/body/body_model.h"

namespace femb {

/// The velocity maps of `d` (computed on the first call).
const BodyVelocityMaps& MapsOf(const SuperelementBody& body, BodyData& d);

/// d p / d q at fixed w (n x n; per node (dx, dpi) spatial, then d eta): the configuration
/// derivative of the generalized momentum (midpoint iteration matrix; with w = wdot, the
/// configuration derivative of M_g wdot). The maps are MapsOf's (BodyVelocityMaps); into `D`
/// with the temporaries in `scratch` (no allocation once sized).
void MomentumDerivative(const SuperelementBody& body, const BodyVelocityMaps& maps, const BodyVelocity& w,
                        Eigen::MatrixXd& D, BodyScratch& scratch);

// The kernels' shared steps.
// P (system velocities -> local velocities) and the frame's angular velocity map U (3 x n).
void VelocityMaps(const SuperelementBody& body, BodyData& d, Eigen::MatrixXd* P, Eigen::MatrixXd* U);
// G of d(P w) = P G dq at fixed w (n x n, into G), from U and the velocities.
void VelocityMapRate(const SuperelementBody& body, const Eigen::MatrixXd& U, const BodyVelocity& w, Eigen::MatrixXd& G);
// The quadratic part of f_in: M_g G w + (Omega_P - Omega_hat) p - G^T p.
void QuadraticInertia(const SuperelementBody& body, const Eigen::MatrixXd& U, const Eigen::MatrixXd& Mg,
                      const BodyVelocity& w, Eigen::VectorXd& out, BodyScratch& scratch);
// Its derivative by w (exact, O(n^2) products), into D.
void QuadraticInertiaDerivative(const SuperelementBody& body, const Eigen::MatrixXd& U, const Eigen::MatrixXd& Mg,
                                const BodyVelocity& w, Eigen::MatrixXd& D, BodyScratch& scratch);

}  // namespace femb
