// The momentum balance of a superelement body, dp/dt = s(q, w, p) + applied - elastic forces
// (the midpoint scheme's form, which conserves linear and angular momentum), and its derivatives.
#pragma once

#include "solver/body/body_model.h"

namespace femb {

/// The momentum balance in the form dp/dt = s(q, w, p) + applied - elastic forces, with
///   s = G^T p + Omega_hat p    (dT/dq at fixed spatial velocities, and omega_k x p_k on the
/// rotation rows from the spatial velocities of SO(3)), so that f_in = dp/dt - s. Here p is
/// any vector (the midpoint scheme passes the momenta of the step's ends). For every p, s has
/// no resultant and its moment about the origin is sum_k p_x,k x xdot_k: this is what makes the
/// midpoint scheme of dynamic_analysis.h conserve linear and angular momentum exactly.
/// Into `out` with the temporaries in `scratch` (no allocation once sized).
void MomentumSource(const SuperelementBody& body, const BodyVelocityMaps& maps, const BodyVelocity& w,
                    const Eigen::VectorXd& p, Eigen::VectorXd& out, BodyScratch& scratch);

/// The whole source at `d` for the body's own kinetic energy: with the exact inertia
///   s = G^T p + Omega_hat p + Rbar B^T g,
/// g = dT/dq_loc at fixed frame-axes velocities Rbar^T w (the local coordinates' own share:
/// the invariants' explicit terms and the turning of the maps Z, B with q_loc; see
/// ExactMomentumSource), which, orthogonal to every rigid motion, adds no resultant and no
/// moment: the midpoint scheme keeps conserving momentum. Here p is the exact momentum
/// MassTimes(d, w) for the G^T p part only where the caller passes it so; the local term
/// takes the momentum of w at d itself. Without the exact inertia: MomentumSource(MapsOf(d)).
void MomentumSource(const SuperelementBody& body, BodyData& d, const BodyVelocity& w, const Eigen::VectorXd& p,
                    Eigen::VectorXd& out);

/// Derivatives of MomentumSource s(q, w, p) with respect to w and to p (both n x n; s is
/// bilinear in w and p), with the temporaries in `scratch` (no allocation once d_w, d_p are sized).
void MomentumSourceDerivatives(const SuperelementBody& body, const BodyVelocityMaps& maps, const BodyVelocity& w,
                               const Eigen::VectorXd& p, Eigen::MatrixXd& d_w, Eigen::MatrixXd& d_p,
                               BodyScratch& scratch);

/// d p / d q at fixed w of the body's own momentum p = MassTimes(d, w) (the midpoint scheme's
/// iteration matrix): MomentumDerivative for the corotational inertia; for the exact one the
/// frame's turning as MomentumDerivative with the exact mass plus the local coordinates' share
/// Rbar (d p_hat / d q_loc) B Rbar^T, the middle factor by central differences in q_loc (that
/// share turns the torsion of a spinning bar, whose inertia is small, as much as the frame's:
/// without it Newton stalled there). `side`: the perturbed data (storage reused).
void MomentumConfigurationTangent(const SuperelementBody& body, BodyData& d, const BodyVelocity& w, BodyData& side,
                                  Eigen::MatrixXd& D);

/// With the exact inertia: adds to `d_w` the derivative of the source's local term (the
/// MomentumSource at `d` beyond G^T p + Omega_hat p) with respect to w, by central
/// differences that are exact up to round-off (the term is quadratic in w).
void AddLocalSourceVelocityDerivative(const SuperelementBody& body, BodyData& d, const BodyVelocity& w,
                                      Eigen::MatrixXd& d_w);

}  // namespace femb
