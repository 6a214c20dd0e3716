// One assembly pass over the bodies, shared by statics (system.h, AssembleStatic), generalized-alpha
// and Radau IIA (solver/integrators/generalized_alpha.cpp) and the midpoint scheme
// (solver/integrators/midpoint.cpp): each body's share (BodyTerms) evaluated on its own, on the
// threads when there are several, then added into the system in body order, so that the sums are
// the same bits whatever thread computed a body. A pass keeps its storage (BodyPass, BodyTerms,
// AssemblyParts) from one Newton iteration to the next and allocates nothing once sized.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "solver/assembly/system.h"
#include "solver/parallel.h"

namespace femb {

/// The system's share of a dynamic pass: its residual, the matrices when built, and the scales of
/// Newton's convergence test.
struct Assembly {
  bool ok = true;
  std::string message;
  Eigen::VectorXd residual;  ///< f_ext + f_grav - f_int - f_in
  Eigen::VectorXd f_ext;     ///< nodal loads and gravity, for the work
  SystemMatrix K, C, M;
  double scale = 0.0;
  /// Per unknown: the largest force scale of the bodies acting on it, floored by the loads' and
  /// springs' (the model's `scale` where no body acts: loop multipliers). Newton's test weighs
  /// each unknown's residual by it (ScaledFreeNorm), so that one stiff body's forces set the
  /// tolerance of its own unknowns only.
  Eigen::VectorXd dof_scale;
  double roundoff = 0.0;   ///< residual noise from the round-off of absolute positions
  NodeForces node_forces;  ///< per node, residual sense (for the reactions)
};

/// The triplets of an assembly in progress and the node forces for the joints' stiffness; the
/// loads' and springs' vectors and the weights of FinishAssembly, and the system-level functions'
/// scratch (storage kept: an assembly allocates nothing once they have their sizes).
struct AssemblyParts {
  Triplets K, C, M;
  NodeForces node_forces;
  Eigen::VectorXd loads, springs, weights;
  SystemScratch scratch;
};

/// Starts an assembly in `out` (residual and f_ext zero, parts emptied): storage reused.
void StartAssembly(const SystemModel& model, const DofMap& dofs, AssemblyParts& parts, Assembly& out);

/// Nodal loads at t, spring-dampers at velocities W (both on `config`), and with `matrices` their
/// and the joints' geometric stiffness into parts.K and parts.C (the caller builds the matrices).
void FinishAssembly(const SystemModel& model, const DofMap& dofs, const SystemState& config, double t,
                    const Eigen::VectorXd& W, bool matrices, AssemblyParts& parts, Assembly& out);

/// f(b) for every body, on the pool when there is one (f is called, never copied).
template <class F>
void ForEachBody(BodyThreads* threads, int n, const F& f) {
  if (threads) {
    threads->ForEach(n, f);
  } else {
    for (int b = 0; b < n; ++b) f(b);
  }
}

/// One body's evaluation in a pass, kept for the matrices of the same state (the dynamic
/// iteration matrix, AddDynamicMatrices) and for the measures of a converged step.
struct BodyPass {
  BodyData data;
  Eigen::VectorXd w, wdot;  ///< the body's velocities and accelerations (zero at rest)
  InertiaLoadFactors load;
};

/// One body's share of an assembly pass, computed on its own (in parallel with the others) and
/// added into the system in body order (AddBodyTerms; statics: AssembleStatic's own sum).
struct BodyTerms {
  bool frame_ok = true;
  Eigen::VectorXd r_b, f_grav;  ///< f_grav - f_int - f_in (at rest: -f_int), and f_grav
  Eigen::MatrixXd K;            ///< statics' tangent of f_int - f_grav (empty in a dynamic pass)
  double scale = 0.0, roundoff = 0.0;
  double elastic_energy = 0.0;  ///< at rest (statics)
  std::vector<MapEntry> map;
  Eigen::VectorXd f_int, f_in, f_acc, f_quadratic;  ///< the pass's scratch (storage kept)
};

/// What a pass evaluates a body in: at rest (statics: no inertia; the weight, ramped by the load
/// factor, counts with the applied loads) or in motion at pass.w and pass.wdot (a dynamic pass).
struct BodyPassKind {
  bool at_rest = false;
  bool warm_frame = false;       ///< PlaceBody's `warm`: the frame iterated from the last pass's
  double inertia_factor = 0.0;   ///< the mass's factor in the iteration matrix (RoundOffForce)
  bool elastic_tangent = false;  ///< at rest: the tangent of f_int - f_grav into r.K
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();
};

/// Body b's share of a pass at config (its frame placed from config.frames[b], which it updates),
/// with pass.w and pass.wdot set by the caller (zero at rest): the internal force with the
/// inertia stiffening of that motion and `kind.gravity` (StiffenedElasticForce), the weight, in
/// motion the inertia force with modal damping; the force scale of each term on its own, the
/// round-off of the forces and the body's map. In motion r_b = f_grav - f_int - f_in and the scale
/// counts every term; at rest r_b = -f_int, the weight stays apart in f_grav (statics adds it to
/// the loads, whose size floors every unknown's scale) and the scale is the internal force's.
/// r.frame_ok false when the frame did not converge (nothing else evaluated).
void EvaluateBodyTerms(const SystemModel& model, const DofMap& dofs, SystemState& config, int b,
                       const BodyPassKind& kind, BodyPass& pass, BodyTerms& r);

/// Adds the bodies' terms in body order: the same sums whatever thread computed them. False (the
/// message in `out`) when a body's floating frame did not converge.
bool AddBodyTerms(const SystemModel& model, const std::vector<BodyTerms>& terms, AssemblyParts& parts, Assembly& out);

/// The storage of static passes kept from one Newton iteration to the next.
struct StaticWorkspace {
  std::vector<BodyPass> passes;
  std::vector<BodyTerms> terms;
  AssemblyParts parts;
  Eigen::VectorXd gravity;  ///< the bodies' weight over the coordinates
  TripletAssembler tangent;
};

}  // namespace femb
