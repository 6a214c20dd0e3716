// The elastic force of a superelement body and its tangent (thesis 4.12, 4.25-4.37; the
// tangent stiffness paper), with the file's polynomial force (modal derivatives, geometric
// stiffening) and the inertia load cases' stiffness; the interface constraint of a basis that
// moves fewer interface directions (thesis 8.2 case 4); the residual's round-off.
#pragma once

#include "solver/body/body_model.h"

namespace femb {

/// Elastic force f (6N + m; per node force then moment, global axes; then modal forces) and,
/// if `tangent` is not null, its derivative with respect to (dx_k, dpi_k, d eta).
/// With `load` (and a file with inertia stiffening) the local stiffness is K + K_sigma(a)
/// (InertiaLoads); `d_load` (n x 12) then receives df/da at fixed configuration.
void ElasticForce(const SuperelementBody& body, BodyData& d, Eigen::VectorXd* f, Eigen::MatrixXd* tangent,
                  const InertiaLoadFactors* load = nullptr, Eigen::MatrixXd* d_load = nullptr);

/// Strain energy q_loc^T K q_loc / 2.
double ElasticEnergy(const SuperelementBody& body, BodyData& d);

/// At `d`: g = C q_int (r); G = dg/dq = C B Rbar^T on the body's coordinates (r x n, exact: the
/// local map of the file comment); with `lambda`, H = d(G^T lambda)/dq (n x n). G^T lambda is
/// the elastic force's form Rbar B^T Q with the local force Q = [C^T lambda; 0], which does not
/// depend on the configuration: H is that force's K2 + K3 + K4 (tangent stiffness paper).
void InterfaceConstraint(const SuperelementBody& body, BodyData& d, Eigen::VectorXd* g, Eigen::MatrixXd* G,
                         const Eigen::VectorXd* lambda, Eigen::MatrixXd* H);

/// The residual noise that the round-off of absolute node positions of magnitude |x| causes
/// in the elastic force and, in a time step whose iteration matrix takes the mass times
/// `inertia_factor` (generalized-alpha beta', the midpoint scheme 2 / h^2: the accelerations
/// are position differences over h^2), in the inertia force (ForceNorm units):
/// eps |x| (16 sqrt(n) max|D K D| + 4 inertia_factor max|D M D|): the inertia's share is the
/// round-off of the position differences in the momenta of a step (measured: the midpoint
/// scheme's residual on a rigid four-bar at h = 5 us stalls at 1.25 times eps |x| 2 beta' |M|;
/// 16 sqrt(n) there let it stop short of its invariants at Newton tolerance 1e-12). Far from
/// the origin (1e4 m), or with steps of microseconds, it exceeds a relative Newton tolerance;
/// the analyses accept a residual below it.
double RoundOffForce(const SuperelementBody& body, const BodyConfiguration& c, double inertia_factor = 0.0);

// The kernels' shared steps.
// Local internal force and its tangent: K q or the polynomial's.
// The force is kept in d (BodyData::local_force) for the next call with the same load factors.
const Eigen::VectorXd& LocalForce(const SuperelementBody& body, BodyData& d, const InertiaLoadFactors* load = nullptr);
// Into K.
void LocalTangent(const SuperelementBody& body, BodyData& d, const InertiaLoadFactors* load, Eigen::MatrixXd& K);
// The condensed polynomial's eps at d (geometric stiffening without modal derivatives), kept in d.
const Eigen::VectorXd& Condensed(const SuperelementBody& body, BodyData& d);
// K2 + K3 + K4 of a local force Q (Qhat = B^T Q, or T0^T Q when `approximated`: K3 alone),
// added to the local Kt (not turned by Rbar).
void AddGeometricTangent(const SuperelementBody& body, BodyData& d, const Eigen::VectorXd& Q,
                         const Eigen::VectorXd& Qhat, bool approximated, Eigen::MatrixXd& Kt);

}  // namespace femb
