// The system's assembly: the static residual and tangent, nodal loads and spring-dampers, and
// the maps between the bodies' local vectors and the system's coordinates (gather, scatter,
// triplets). The model, its state and numbering are in system_model.h; the joint tree in
// solver/joints/joint_tree.h; the closed loops in solver/joints/loop_constraints.h; the linear
// solver in free_solver.h (all included here).
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "solver/assembly/free_solver.h"
#include "solver/assembly/system_model.h"
#include "solver/joints/joint_tree.h"
#include "solver/joints/loop_constraints.h"

namespace femb {

/// Result of an evaluation of internal and external forces.
struct SystemForces {
  bool ok = true;
  std::string message;       ///< what failed (a floating frame did not converge, ...)
  Eigen::VectorXd residual;  ///< lambda f_ext - f_int over the unknowns
  SystemMatrix tangent;      ///< d(f_int - lambda f_ext)/d(unknowns)
  double elastic_energy = 0.0;
  double force_scale = 0.0;   ///< largest norm of the internal or external force terms
  Eigen::VectorXd dof_scale;  ///< per unknown: the force scale of the bodies acting on it (ScaledFreeNorm)
  double roundoff = 0.0;      ///< residual noise from the round-off of absolute positions
  NodeForces node_forces;     ///< per node, residual sense (applied minus internal)
  Eigen::VectorXd loads;      ///< the nodal loads alone, over the coordinates (for their work)
};

class BodyThreads;
struct StaticWorkspace;

/// Solves every body's floating frame (updating state.frames) and assembles the static
/// residual and tangent at load factor `lambda`: the bodies at rest in the pass shared with the
/// dynamic integrators (EvaluateBodyTerms, body_pass.h), on `threads` when given, in `work`'s
/// storage when given (kept between Newton iterations, nothing allocated for the bodies).
SystemForces AssembleStatic(const SystemModel& model, const DofMap& dofs, SystemState& state, double lambda,
                            bool with_tangent, StaticWorkspace* work = nullptr, BodyThreads* threads = nullptr);

/// External nodal loads at time t (or load factor) and their stiffness d(-f_ext)/dq added to
/// `tangent` when not null (follower loads).
void AddNodeLoads(const SystemModel& model, const SystemState& state, double t, Eigen::VectorXd& residual,
                  Triplets* tangent, NodeForces* node_forces = nullptr);

/// The user's forces (SystemModel::user_forces, solver/forces/user_force.h) at time t (statics:
/// the load factor) added to `residual` (as applied forces), -d f / dq to `K` and -d f / dv to
/// `C` and the forces to `node_forces`, each when not null. W may be empty (at rest). A user
/// function's failure throws UserForceError.
void AddUserForces(const SystemModel& model, const SystemState& state, const Eigen::VectorXd& W, double t,
                   Eigen::VectorXd* residual, Triplets* K, Triplets* C, NodeForces* node_forces);

/// Spring-damper forces added to `residual` (as applied forces), their stiffness and damping
/// (of -f) to `K`, `C`, their energy to `energy`, each when not null. W may be empty (static).
void AddSpringDampers(const SystemModel& model, const SystemState& state, const Eigen::VectorXd& W,
                      Eigen::VectorXd* residual, Triplets* K, Triplets* C, double* energy,
                      NodeForces* node_forces = nullptr, SystemScratch* scratch = nullptr);

/// Gathers body b's velocities (xdot, omega per interface node, then etadot) from the
/// coordinate velocities W.
Eigen::VectorXd GatherBody(const SystemModel& model, const DofMap& dofs, const SystemState& state, int b,
                           const Eigen::VectorXd& W);
/// The same into `w` (its storage reused).
void GatherBody(const SystemModel& model, const DofMap& dofs, const SystemState& state, int b, const Eigen::VectorXd& W,
                Eigen::VectorXd& w);
/// Body b's node accelerations (with the joints' convective terms) and modal accelerations.
Eigen::VectorXd GatherBodyAcceleration(const SystemModel& model, const DofMap& dofs, int b,
                                       const std::vector<Eigen::Matrix<double, 6, 1>>& node_acc,
                                       const Eigen::VectorXd& Wdot);
void GatherBodyAcceleration(const SystemModel& model, const DofMap& dofs, int b,
                            const std::vector<Eigen::Matrix<double, 6, 1>>& node_acc, const Eigen::VectorXd& Wdot,
                            Eigen::VectorXd& w);

std::vector<MapEntry> BodyMap(const SystemModel& model, const DofMap& dofs, const SystemState& state, int b);
/// The same into `map` (its storage reused).
void BodyMap(const SystemModel& model, const DofMap& dofs, const SystemState& state, int b, std::vector<MapEntry>& map);
/// Adds body b's local vector (residual sense) to the node forces.
void AddBodyNodeForces(const SystemModel& model, int b, const Eigen::VectorXd& r_b, NodeForces& forces);

/// Scatters a body vector f (n_b) and matrix K (n_b x n_b) through the map: F += B^T f,
/// KK += B^T K B.
void ScatterBody(const std::vector<MapEntry>& map, const Eigen::VectorXd* f, const Eigen::MatrixXd* K,
                 Eigen::VectorXd* F, Triplets* KK);

/// Builds an n x n sparse matrix from triplets (duplicates summed).
SystemMatrix ToMatrix(int n, const Triplets& triplets);

/// ToMatrix for triplets that come with the same rows and columns in the same order time after
/// time (an assembly of a fixed model): the first build sorts them and keeps, for each triplet,
/// its slot in the compressed matrix; the next ones with the same sequence only add the values
/// into their slots (no sorting, no allocation; sums in triplet order, as setFromTriplets).
class TripletAssembler {
 public:
  const SystemMatrix& Build(int n, const Triplets& triplets);
  long rebuilds() const { return rebuilds_; }
  /// Exchanges the two assemblers' patterns and matrices (no allocation).
  void swap(TripletAssembler& other) {
    matrix_.swap(other.matrix_);
    rows_.swap(other.rows_);
    cols_.swap(other.cols_);
    slots_.swap(other.slots_);
    std::swap(rebuilds_, other.rebuilds_);
  }

 private:
  SystemMatrix matrix_;
  std::vector<int> rows_, cols_, slots_;
  long rebuilds_ = 0;
};

/// Weights that make a vector over the coordinates (a residual) a vector of forces whatever the
/// unit system: 1 for translation coordinates, 1/L for rotation coordinates (moments over the
/// model's size L: the diagonal of its nodes' bounding box), sqrt(m_b) for body b's modal
/// coordinates (mass-normalized: their forces are force / sqrt(mass)). Newton's convergence test
/// on the weighted norm gives the same answer in SI and in mm-t-s.
Eigen::VectorXd ResidualWeights(const SystemModel& model, const DofMap& dofs);
void ResidualWeights(const SystemModel& model, const DofMap& dofs, Eigen::VectorXd& w);
/// Weighted norm of r over the coordinates solved for.
double FreeNorm(const DofMap& dofs, const Eigen::VectorXd& r, const Eigen::VectorXd& weights);
/// sqrt(sum_j (w_j r_j / s_j)^2) over the solved unknowns (w: the residual weights, s: per
/// unknown, the force scale of the bodies acting on it, SystemForces::dof_scale or
/// dynamic_internal::Assembly::dof_scale): the residual relative to the forces in balance on each
/// unknown, Newton's convergence measure.
double ScaledFreeNorm(const DofMap& dofs, const Eigen::VectorXd& r, const Eigen::VectorXd& weights,
                      const Eigen::VectorXd& scale);
/// Adds a body's force scale to the unknowns its map reaches (dof_scale[j] = max(., scale)).
void AddBodyScale(const std::vector<MapEntry>& map, double scale, Eigen::VectorXd& dof_scale);
/// Finishes a dof_scale: unknowns a body reaches floored by `applied` (the loads' and springs'
/// norm), the others (no body: loop multipliers) at the model's scale `whole`.
void FinishDofScale(double applied, double whole, Eigen::VectorXd& dof_scale);

}  // namespace femb
