// A multibody system of superelements on shared 6-DOF nodes, with Lagrange multipliers only
// where a loop of joints must be closed (cut joints, solver/joints/loop_closure.h).
// Nodes shared by bodies are rigid connections. Each node k moves in a subspace of its spatial
// increments (dx, dpi): dq_k = S_k dz_k with its own coordinates z_k — S_k = 1 for a free
// node, nothing for a clamp, [0; 1] for a spherical joint to ground, [0; a] for a revolute joint
// to ground about the fixed axis a (R = exp(phi a~) R0 exactly), [a; 0] prismatic, [a 0; 0 a]
// cylindrical. S_k is constant, so these joints add neither geometric nor convective terms.
// A node may instead depend on a parent node through a NodeJoint (solver/joints/node_joint.h)
// with the joint's own coordinates; its increments then follow dq_c = A dq_p + B dz, composed
// down the tree into the node Jacobian J_k (dq_k = J_k dz), with the joints' geometric
// stiffness and convective accelerations.
// Unknowns: every node's coordinates, then the modal coordinates of every body. A joint
// coordinate may be prescribed by a time function: it stays in the vector of coordinates but
// is not solved for. Model (immutable) and State are separate: f(const Model&, State&).
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <Eigen/SparseCore>
#include <memory>
#include <array>
#include <functional>
#include <string>
#include <vector>

#include "solver/body/superelement_body.h"
#include "solver/forces/spring_damper.h"
#include "solver/joints/loop_closure.h"
#include "solver/joints/node_joint.h"

namespace femb {

/// A force and moment on a node, scaled by the load factor. `follower`: given in the node's
/// frame and turning with it; else fixed in space.
struct NodeLoad {
  int node = -1;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  bool follower = false;
  /// Time function scaling the load (static: pseudo-time = load factor). Empty: identity.
  std::function<double(double)> scale;
  double Scale(double t) const { return scale ? scale(t) : t; }
};

struct SystemModel {
  std::vector<std::string> node_names;
  std::vector<Eigen::Vector3d> node_x0;   ///< initial positions
  std::vector<Eigen::Matrix3d> node_R0;   ///< initial rotations
  /// Per node: the basis S_k (6 x d_k) of its allowed spatial increments (see above).
  std::vector<Eigen::MatrixXd> motion;
  /// Prescribed node coordinates: node, coordinate index in z_k, value f(t), f'(t), f''(t).
  struct Prescribed {
    int node = -1;
    int coordinate = 0;
    std::function<double(double)> value, rate, acceleration;
  };
  std::vector<Prescribed> prescribed;
  /// Joints between nodes: each child node depends on its parent (a tree; no cycles).
  std::vector<NodeJoint> joints;
  /// Joints that close loops of that tree: constraint equations with Lagrange multipliers
  /// (solver/joints/loop_closure.h); their child keeps its own coordinates.
  std::vector<CutJoint> cut_joints;
  std::vector<SuperelementBody> bodies;
  std::vector<std::vector<int>> body_nodes;  ///< system node of each interface of each body
  std::vector<std::string> body_names;       ///< for messages (may be empty)
  std::vector<NodeLoad> loads;
  std::vector<SpringDamper> springs;
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();  ///< uniform acceleration field
  /// Static analyses: gravity grows linearly with the pseudo-time to full at this value (the
  /// analysis' end_time); 0: no gravity in AssembleStatic (dynamic analyses add it themselves).
  double static_gravity_end = 0.0;

  int n_nodes() const { return int(node_names.size()); }
};

/// System matrices are sparse (assembled from triplets) and factorized sparse (FreeSolver);
/// analyses that need a dense matrix (the tangent's inertia, singular motions) do so below
/// kDenseLimit free coordinates.
using SystemMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
using Triplets = std::vector<Eigen::Triplet<double>>;
inline constexpr int kDenseLimit = 400;
/// Newton tolerances (residual relative to the force scale) below this are under the round-off
/// floor of the residual: the analyses use this instead and say so.
inline constexpr double kRoundOffTolerance = 1e-13;

/// dq_k = J_k dz for one node: sparse columns (coordinate, 6-vector).
using NodeJacobian = std::vector<std::pair<int, Eigen::Matrix<double, 6, 1>>>;

struct SystemState {
  std::vector<Eigen::VectorXd> z;           ///< per node: accumulated coordinates (joint values)
  std::vector<NodeJacobian> J;              ///< per node, at this configuration
  std::vector<Eigen::Vector3d> x;
  std::vector<Eigen::Matrix3d> R;
  std::vector<Eigen::VectorXd> eta;         ///< per body
  std::vector<FrameSolution> frames;        ///< per body, the last solved floating frame
  Eigen::VectorXd lambda;                   ///< the cut joints' multipliers (DofMap::multiplier_first)
};

/// Numbering of the unknowns (coordinates).
class DofMap {
 public:
  explicit DofMap(const SystemModel& model);
  int n_dofs() const { return n_dofs_; }
  /// First coordinate of node k and how many it has (its basis S_k when independent; its
  /// joint's coordinates when it depends on a parent).
  int node_first(int k) const { return node_first_[k]; }
  int node_count(int k) const { return node_count_[k]; }
  const Eigen::MatrixXd& S(int k) const { return (*motion_)[k]; }
  /// The joint making node k dependent, or -1.
  int joint_of(int k) const { return joint_of_[k]; }
  /// Nodes, parents before children.
  const std::vector<int>& order() const { return order_; }
  /// First coordinate of body b's modal coordinates.
  int mode_dof(int b) const { return mode_dof_[b]; }
  /// The unknowns after the coordinates: the multipliers of the cut joints' kept equations
  /// (cut joint c's from multiplier_first(c)), n_multipliers() of them; none without loops.
  int n_multipliers() const { return n_dofs_ - first_multiplier_; }
  int multiplier_first(int c) const { return multiplier_first_[c]; }
  int first_multiplier() const { return first_multiplier_; }
  bool multiplier(int j) const { return j >= first_multiplier_; }
  /// Sets the multipliers' entries of a vector over the unknowns to zero (velocities and
  /// accelerations have none).
  void ClearMultipliers(Eigen::VectorXd& v) const {
    if (n_multipliers() > 0) v.tail(n_multipliers()).setZero();
  }

  /// true for prescribed coordinates (not solved for).
  bool prescribed(int j) const { return prescribed_[j]; }
  /// The coordinate of a prescribed entry.
  int prescribed_index(const SystemModel::Prescribed& p) const { return node_first_[p.node] + p.coordinate; }
  /// Indices of the coordinates solved for.
  const std::vector<int>& solved() const { return solved_; }

 private:
  const std::vector<Eigen::MatrixXd>* motion_;
  std::vector<int> node_first_, node_count_, joint_of_, order_, mode_dof_, solved_, multiplier_first_;
  std::vector<bool> prescribed_;
  int n_dofs_ = 0, first_multiplier_ = 0;
};

/// Node k clamped to ground.
void Clamp(SystemModel& model, int k);
/// Node k's position fixed, rotation free (spherical joint to ground).
void Pin(SystemModel& model, int k);
/// Revolute joint to ground about the fixed unit axis a (global): one rotation coordinate.
void RevoluteToGround(SystemModel& model, int k, const Eigen::Vector3d& axis);
/// Prismatic joint to ground along a (global): one translation coordinate, rotation fixed.
void PrismaticToGround(SystemModel& model, int k, const Eigen::Vector3d& axis);
/// Cylindrical joint to ground: translation along and rotation about a.
void CylindricalToGround(SystemModel& model, int k, const Eigen::Vector3d& axis);

/// Spatial increment or velocity (dx, dpi) of node k from coordinate increments or rates.
Eigen::Matrix<double, 6, 1> NodeMotion(const SystemState& state, int k, const Eigen::VectorXd& dz);

/// Node accelerations J_k Wdot + convective terms of the joints.
std::vector<Eigen::Matrix<double, 6, 1>> NodeAccelerations(const SystemModel& model, const DofMap& dofs,
                                                           const SystemState& state, const Eigen::VectorXd& W,
                                                           const Eigen::VectorXd& Wdot);

/// The derivative of the joints' convective accelerations (NodeAccelerations) with respect to
/// the coordinate velocities W, per node as sparse columns (coordinate, 6-vector); empty for
/// nodes without joints above them. Quadratic in W: the Coriolis and centripetal terms of a
/// chain of joints with offsets, whose share d f_in / dW = M_b dc/dW belongs in the iteration
/// matrix's C (without it Newton converged linearly on a rigid four-bar, 2 iterations a step).
std::vector<NodeJacobian> ConvectiveVelocityDerivative(const SystemModel& model, const DofMap& dofs,
                                                       const SystemState& state, const Eigen::VectorXd& W);

/// The derivative of the node accelerations J_k(q) Wdot + c_k(q, W) (NodeAccelerations) with
/// respect to the coordinates at fixed W and Wdot, per node as sparse columns; empty for nodes
/// without joints above them; down the tree with the joints' maps (no state copies). Its share
/// M_b d(acc)/dq belongs in the iteration matrix's K (on a rigid four-bar it was half of K).
std::vector<NodeJacobian> NodeAccelerationConfigurationDerivative(const SystemModel& model, const DofMap& dofs,
                                                                  const SystemState& state, const Eigen::VectorXd& W,
                                                                  const Eigen::VectorXd& Wdot);

/// Places the dependent nodes from their parents and recomputes the node Jacobians.
void UpdateKinematics(const SystemModel& model, const DofMap& dofs, SystemState& state);

/// Forces in node space (residual sense: applied minus internal) and their derivatives,
/// mapped to the coordinates by the node Jacobians, plus the joints' geometric stiffness.
struct NodeForces {
  std::vector<Eigen::Matrix<double, 6, 1>> f;
  void Add(int k, const Eigen::Matrix<double, 6, 1>& v) { f[k] += v; }
};
NodeForces ZeroNodeForces(const SystemModel& model);
/// tangent -= d(sum_k J_k^T f_k)/dz at fixed f (the joint maps' configuration dependence).
void AddJointGeometricStiffness(const SystemModel& model, const DofMap& dofs, const SystemState& state,
                                const NodeForces& forces, Triplets& tangent);

/// Support and joint reactions at a converged state: for every node held by something (a
/// support: a motion basis of fewer than 6 columns; or a parent node through a joint), the force
/// and moment (global axes, moment about the node) that the support or the parent exerts on the
/// node and all that hangs from it: R_k = -t_k, t_k = f_k + sum over child joints A_c^T t_c, f
/// the node forces of the assembly (applied minus internal and inertia forces). For a prescribed
/// joint coordinate the reaction includes the drive: e.g. a driven revolute's moment about its
/// axis is the driving torque. A node that is the child of cut joints and held otherwise by
/// nothing or by a rigid joint (a rigid body's point): the cut joints' reactions
/// (CutJointReactions). Other nodes: zero.
std::vector<Eigen::Matrix<double, 6, 1>> JointReactions(const SystemModel& model, const DofMap& dofs,
                                                        const SystemState& state, const NodeForces& forces);

/// The cut joints' constraint equations at `state` with its multipliers lambda: the residual's
/// coordinate rows get -G^T lambda and its multiplier rows -g (Newton's S delta = r then asks
/// G dq = -g), the node forces -G_node^T lambda (so AddJointGeometricStiffness adds the tree
/// joints' share of their stiffness). With `tangent`: G in the multipliers' rows, G^T in their
/// columns and d(G^T lambda)/dq through the node Jacobians -- those of the blocks in `blocks`
/// (the midpoint scheme takes them from different configurations). With `jacobian`: G and G^T.
enum LoopBlocks { kLoopRows = 1, kLoopColumns = 2, kLoopHessian = 4, kLoopAll = 7 };
void AddLoopConstraints(const SystemModel& model, const DofMap& dofs, const SystemState& state,
                        Eigen::VectorXd* residual, Triplets* tangent, NodeForces* node_forces,
                        Triplets* jacobian = nullptr, int blocks = kLoopAll);
/// The largest violation of the kept equations: positions in length units, rotations (dot
/// products) times the model's size L so that both are lengths; 0 without loops. `worst`: the
/// cut joint with it (-1 without loops).
double LoopViolation(const SystemModel& model, const SystemState& state, int* worst = nullptr);
/// Per cut joint, the force and moment (global axes, moment about the child node) that the
/// joint's parent node, or the ground, exerts on its child node through the joint: -G_c^T lambda,
/// G_c the child's columns of the kept equations. Along a dropped (redundant) direction the
/// mechanism's reactions are not unique and this one carries none.
std::vector<Eigen::Matrix<double, 6, 1>> CutJointReactions(const SystemModel& model, const SystemState& state);
/// Newton's test on the loops: no cut joints, or LoopViolation <= tolerance times the model's
/// size (BoundingDiagonal of the nodes), the same relative tolerance as the forces'.
bool LoopsClosed(const SystemModel& model, const SystemState& state, double tolerance);

/// Drops the cut joints' equations that repeat others at the initial state (an over-constrained
/// mechanism: a planar four-bar of spatial revolute joints has 3 of its 5 closure equations
/// satisfied by the plane itself). Row by row in order, each equation of the constraint
/// Jacobian on the coordinates solved for (columns scaled to unit size: any units) is kept when
/// it is independent of those kept before it (Gram-Schmidt, relative remainder above 1e-8).
/// Returns per cut joint what its dropped equations held ("" when none). The reactions of a
/// redundant loop are then one of many that balance it (statically indeterminate), as in any
/// multibody code.
std::vector<std::string> DropRedundantEquations(SystemModel& model);

/// Closed loops at `state`: the cut joint whose kept equation is nearest to depending on the
/// others (its row of the constraint Jacobian within 0.05, relative, of the span of the rows
/// before it) -- the mechanism at or near a dead point, where Newton fails or the motion runs
/// away -- named with the equation; "" when none (or no loops).
std::string LoopSingularity(const SystemModel& model, const SystemState& state);

/// Adds an interface node to `model` at a position and returns its index.
int AddNode(SystemModel& model, const std::string& name, const Eigen::Vector3d& x,
            const Eigen::Matrix3d& R = Eigen::Matrix3d::Identity());

/// The initial state: nodes at their initial placement, modes at rest, frames at the bodies'
/// undeformed frames, node Jacobians computed.
SystemState InitialState(const SystemModel& model);

/// Result of an evaluation of internal and external forces.
struct SystemForces {
  bool ok = true;
  std::string message;            ///< what failed (a floating frame did not converge, ...)
  Eigen::VectorXd residual;       ///< lambda f_ext - f_int over the unknowns
  SystemMatrix tangent;           ///< d(f_int - lambda f_ext)/d(unknowns)
  double elastic_energy = 0.0;
  double force_scale = 0.0;       ///< largest norm of the internal or external force terms
  double roundoff = 0.0;          ///< residual noise from the round-off of absolute positions
  NodeForces node_forces;         ///< per node, residual sense (applied minus internal)
  Eigen::VectorXd loads;          ///< the nodal loads alone, over the coordinates (for their work)
};

/// Solves every body's floating frame (updating state.frames) and assembles the static
/// residual and tangent at load factor `lambda`.
SystemForces AssembleStatic(const SystemModel& model, const DofMap& dofs, SystemState& state, double lambda,
                            bool with_tangent);

/// External nodal loads at time t (or load factor) and their stiffness d(-f_ext)/dq added to
/// `tangent` when not null (follower loads).
void AddNodeLoads(const SystemModel& model, const SystemState& state, double t, Eigen::VectorXd& residual,
                  Triplets* tangent, NodeForces* node_forces = nullptr);

/// Spring-damper forces added to `residual` (as applied forces), their stiffness and damping
/// (of -f) to `K`, `C` when not null, their energy to `energy`. W may be empty (static).
void AddSpringDampers(const SystemModel& model, const SystemState& state, const Eigen::VectorXd& W,
                      Eigen::VectorXd& residual, Triplets* K, Triplets* C, double* energy,
                      NodeForces* node_forces = nullptr);

/// Gathers body b's velocities (xdot, omega per interface node, then etadot) from the
/// coordinate velocities W.
Eigen::VectorXd GatherBody(const SystemModel& model, const DofMap& dofs, const SystemState& state, int b,
                           const Eigen::VectorXd& W);
/// Body b's node accelerations (with the joints' convective terms) and modal accelerations.
Eigen::VectorXd GatherBodyAcceleration(const SystemModel& model, const DofMap& dofs, int b,
                                       const std::vector<Eigen::Matrix<double, 6, 1>>& node_acc,
                                       const Eigen::VectorXd& Wdot);

/// The linear map from coordinates to body b's local coordinate increments as (local index,
/// coordinate, coefficient) entries: dq_b[i] = sum c dz[j].
struct MapEntry {
  int local;
  int coordinate;
  double coefficient;
};
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

 private:
  SystemMatrix matrix_;
  std::vector<int> rows_, cols_, slots_;
  long rebuilds_ = 0;
};

/// Sets the prescribed coordinates to their values at t: configuration (through the node's
/// basis), and, when W / Wdot are given, their rates and accelerations.
void ApplyPrescribed(const SystemModel& model, const DofMap& dofs, double t, SystemState& state,
                     Eigen::VectorXd* W, Eigen::VectorXd* Wdot);

/// Solves S d = r on the coordinates that are not prescribed (prescribed ones: d = 0) with
/// FreeSolver.
Eigen::VectorXd SolveFree(const DofMap& dofs, const SystemMatrix& S, const Eigen::VectorXd& r);

/// The sparse LU factor of S on the coordinates solved for, kept for several solves (Jacobian
/// reuse): Factor once, Solve many times. KLU (SuiteSparse; Davis & Palamadai Natarajan 2010,
/// made for the repeated factorizations of one sparsity pattern in circuit simulation): its
/// ordering (block triangular form, then AMD on each block) is computed once per pattern, and a
/// factorization with the same pattern reuses the analysis and, while its pivots stay good
/// (the ratio of its smallest to its largest pivot within 1e-3 of the last full factorization's), the
/// pivot order (klu_refactor); otherwise it pivots anew (klu_factor). Factor returns false when
/// the matrix is singular: a zero pivot or a condition estimate of the matrix scaled to unit
/// diagonal (D S D) above 1e15.
class FreeSolver {
 public:
  FreeSolver();
  ~FreeSolver();
  FreeSolver(const FreeSolver&) = delete;
  FreeSolver& operator=(const FreeSolver&) = delete;
  bool Factor(const DofMap& dofs, const SystemMatrix& S);
  Eigen::VectorXd Solve(const Eigen::VectorXd& r) const;
  bool valid() const { return valid_; }
  void Invalidate() { valid_ = false; }
  /// Sparsity patterns analysed, factorizations that pivoted anew (klu_factor), and those that
  /// reused the pivot order (klu_refactor).
  long analyses() const { return analysed_; }
  long full_factorizations() const { return full_; }
  long refactorizations() const { return refactored_; }

 private:
  struct Klu;
  std::unique_ptr<Klu> klu_;
  std::vector<int> free_, position_;
  Eigen::VectorXd scale_;  ///< per free unknown: 1, or a multiplier's scaling (see Factor)
  bool valid_ = false;
  long analysed_ = 0, full_ = 0, refactored_ = 0;
};
/// S restricted to the coordinates solved for, dense (n_free x n_free).
Eigen::MatrixXd DenseFreeMatrix(const DofMap& dofs, const SystemMatrix& S);

/// The message an analysis gives once when asked for a Newton tolerance below kRoundOffTolerance
/// (empty when the tolerance is fine).
std::string RoundOffToleranceWarning(double tolerance);

/// The diagonal of the bounding box of points (node positions): the model's size; 0 for fewer
/// than two points.
double BoundingDiagonal(const std::vector<Eigen::Vector3d>& points);

/// Weights that make a vector over the coordinates (a residual) a vector of forces whatever the
/// unit system: 1 for translation coordinates, 1/L for rotation coordinates (moments over the
/// model's size L: the diagonal of its nodes' bounding box), sqrt(m_b) for body b's modal
/// coordinates (mass-normalized: their forces are force / sqrt(mass)). Newton's convergence test
/// on the weighted norm gives the same answer in SI and in mm-t-s.
Eigen::VectorXd ResidualWeights(const SystemModel& model, const DofMap& dofs);
/// Weighted norm of r over the coordinates solved for.
double FreeNorm(const DofMap& dofs, const Eigen::VectorXd& r, const Eigen::VectorXd& weights);

/// Applies an increment of the unknowns: x += dx, R <- exp(dpi~) R, eta += d eta.
void ApplyIncrement(const SystemModel& model, const DofMap& dofs, const Eigen::VectorXd& delta, SystemState& state);

/// The body's configuration taken from the system state (into `c`: reusing its storage).
BodyConfiguration BodyConfigurationOf(const SystemModel& model, const SystemState& state, int body);
void BodyConfigurationOf(const SystemModel& model, const SystemState& state, int body, BodyConfiguration& c);

}  // namespace femb
