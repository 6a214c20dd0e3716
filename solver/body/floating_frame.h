// The floating frame of a superelement body (thesis 3.7, 4.2): the frame that solves
// Phi_CB q_loc(x_j, R_j) = 0, the local coordinates it defines, the kinematic maps at a
// configuration (BodyData, Evaluate), and the frame's motion.
#pragma once

#include "solver/body/body_model.h"

namespace femb {

/// Undeformed configuration at the placement, and its floating frame.
BodyConfiguration InitialConfiguration(const SuperelementBody& body);

/// A starting guess for SolveFrame with no previous frame: the frame carried rigidly by
/// interface node 0.
FrameSolution GuessFrame(const SuperelementBody& body, const BodyConfiguration& c);

/// Newton on Phi_CB q_loc(x_j, R_j) = 0 from `guess` (thesis 4.2). ok = false when the
/// residual does not fall below 1e-12 (relative) in 30 iterations. `q`: scratch for the local
/// coordinates (no allocation once sized; on return they are the solution's), or none. With
/// `S_inv` (the inverse frame matrix of a nearby configuration of this body, e.g. its last
/// BodyKinematics::S_inv) the iteration uses it instead of factoring the frame matrix at every
/// iterate: S depends on the deformation only, so it converges as fast while it costs a 6 x 6
/// product per iteration.
FrameSolution SolveFrame(const SuperelementBody& body, const BodyConfiguration& c, const FrameSolution& guess,
                         Eigen::VectorXd* q = nullptr, const Eigen::Matrix<double, 6, 6>* S_inv = nullptr);

/// SolveFrame from the last frame (with `S_inv` first, then full Newton), and failing that
/// from GuessFrame (ok = false if every attempt fails).
FrameSolution SolveFrameFrom(const SuperelementBody& body, const BodyConfiguration& c, const FrameSolution& last,
                             Eigen::VectorXd* q = nullptr, const Eigen::Matrix<double, 6, 6>* S_inv = nullptr);

/// Local coordinates q_loc (6N + m) into `q`.
void LocalCoordinates(const SuperelementBody& body, const BodyConfiguration& c, const FrameSolution& frame,
                      Eigen::VectorXd& q);

/// The body's quantities at configuration `c` with its solved floating frame.
BodyData Evaluate(const SuperelementBody& body, const BodyConfiguration& c, const FrameSolution& frame);
/// The same into `d`, reusing its storage (a body's data kept from one Newton iteration to the
/// next allocates nothing for the kinematics). `c` may be d.c itself.
void Evaluate(const SuperelementBody& body, const BodyConfiguration& c, const FrameSolution& frame, BodyData& d);
/// The same when d.q already holds the local coordinates at `frame` (SolveFrameFrom's output
/// for this c and frame): they are not computed again.
void EvaluateSolved(const SuperelementBody& body, const BodyConfiguration& c, const FrameSolution& frame, BodyData& d);
/// The body at its configuration d.c: the frame solved from `last` (SolveFrameFrom; first with
/// d's own S^-1 when `warm` and d holds this body's kinematics, as a Newton iteration's or a
/// step's last evaluation does) and d evaluated at it. Every assembly pass (statics,
/// generalized-alpha, the midpoint scheme) places its bodies here. The frame, ok = false when it
/// did not converge (d is then not evaluated).
FrameSolution PlaceBody(const SuperelementBody& body, const FrameSolution& last, BodyData& d, bool warm = false);

/// The floating frame's motion and the rates of the local coordinates at `d` (LocalMotion, in
/// body_model.h); the accelerations with `wdot`.
LocalMotion LocalRates(const SuperelementBody& body, BodyData& d, const BodyVelocity& w, const BodyVelocity* wdot);

/// The deformed body's centre of mass (global): x_j + R_j (s_0 + C q_loc) / m, s_0 the first
/// moment of the undeformed body about the frame origin, C = int rho Phi (the translation rows
/// of Phi_rig0^T M), m the mass; from the local coordinates q_loc = LocalCoordinates(c, frame).
Eigen::Vector3d CenterOfMass(const SuperelementBody& body, const Eigen::VectorXd& q_loc, const FrameSolution& frame);

// The kernels' shared steps.
// Into `k`, reusing its storage.
void ComputeKinematics(const SuperelementBody& body, const Eigen::VectorXd& q_loc, BodyKinematics& k);
// S = Phi_CB D Phi_rig alone (the floating frame's Newton iteration), node block by node block.
Eigen::Matrix<double, 6, 6> FrameMatrix(const SuperelementBody& body, const Eigen::VectorXd& q_loc);
// Configuration c with coordinate i moved by sign times its difference step (into `step`).
BodyConfiguration Perturbed(const SuperelementBody& body, const BodyConfiguration& c, int i, double sign, double* step);

}  // namespace femb
