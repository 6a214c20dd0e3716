// A multibody system of superelements on shared 6-DOF nodes, with Lagrange multipliers only
// where a loop of joints must be closed (cut joints, solver/joints/loop_closure.h).
// Nodes shared by bodies are rigid connections. A node is free (its own 6 coordinates: spatial
// increments dq_k = (dx, dpi)) unless it hangs on a NodeJoint (solver/joints/node_joint.h):
// then it depends on its parent node through the joint's own coordinates z (none for a rigid
// joint, one for a revolute, ...), its increments following dq_c = A dq_p + B dz, composed down
// the tree into the node Jacobian J_k (dq_k = J_k dz), with the joints' geometric stiffness and
// convective accelerations. Supports are joints like any other, to the ground (kGround): the
// fixed parent at the origin with world axes and no coordinates. A clamp is a rigid joint to
// the ground, a pin a spherical one, a revolute to the ground turns the node about its fixed
// axis: R = exp(phi a~) R0. One representation for every joint.
// Unknowns: every node's coordinates, the modal coordinates of every body, then the cut
// joints' multipliers and those of the bodies' interface constraints (thesis 8.2 case 4)
// (DofMap::first_multiplier; solver/joints/loop_constraints.h). A joint
// coordinate may be prescribed by a time function: it stays in the vector of coordinates but
// is not solved for. Model (immutable) and State are separate: f(const Model&, State&).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "solver/body/superelement_body.h"
#include "solver/forces/spring_damper.h"
#include "solver/forces/user_force.h"
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

class DofMap;

struct SystemModel {
  std::vector<std::string> node_names;
  std::vector<Eigen::Vector3d> node_x0;  ///< initial positions
  std::vector<Eigen::Matrix3d> node_R0;  ///< initial rotations
  /// Prescribed node coordinates: node, coordinate index in z_k, value f(t), f'(t), f''(t).
  struct Prescribed {
    int node = -1;
    int coordinate = 0;
    std::function<double(double)> value, rate, acceleration;
  };
  std::vector<Prescribed> prescribed;
  /// Joints between nodes and to the ground (parent kGround): each child node depends on its
  /// parent (a tree; no cycles); a node that is no joint's child is free.
  std::vector<NodeJoint> joints;
  /// Joints that close loops of that tree: constraint equations with Lagrange multipliers
  /// (solver/joints/loop_closure.h); their child keeps its own coordinates.
  std::vector<CutJoint> cut_joints;
  std::vector<SuperelementBody> bodies;
  std::vector<std::vector<int>> body_nodes;  ///< system node of each interface of each body
  std::vector<std::string> body_names;       ///< for messages (may be empty)
  std::vector<NodeLoad> loads;
  std::vector<SpringDamper> springs;
  std::vector<UserNodeForce> user_forces;             ///< written by the user (the Python module)
  std::vector<UserModalForce> user_modal_forces;      ///< the same, on bodies' modal coordinates
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();  ///< uniform acceleration field
  /// Static analyses: gravity grows linearly with the pseudo-time to full at this value (the
  /// analysis' end_time); 0: no gravity in AssembleStatic (dynamic analyses add it themselves).
  double static_gravity_end = 0.0;

  int n_nodes() const { return int(node_names.size()); }
  /// Numbers the model's unknowns (DofMap) once its structure is complete: nodes, their supports,
  /// joints, prescribed coordinates, bodies, cut joints (BuildScene does it last). Again after a
  /// change of that structure. An InputError when the joints do not form a tree (a joint naming
  /// a node that does not exist, a node with two parent joints, a cycle).
  void Number();
  /// The numbering Number() made (a copy of the model shares it). The analyses take it from
  /// here instead of each building its own. A std::logic_error when the model was not numbered
  /// or its structure changed since.
  const DofMap& dofs() const;
  /// True with Lagrange multipliers: cut joints, or bodies with an interface constraint.
  bool has_constraints() const {
    if (!cut_joints.empty()) return true;
    for (const SuperelementBody& body : bodies)
      if (body.n_constraints() > 0) return true;
    return false;
  }

 private:
  std::shared_ptr<const DofMap> dofs_;  ///< dofs(), immutable once made
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

/// The linear map from coordinates to body b's local coordinate increments as (local index,
/// coordinate, coefficient) entries: dq_b[i] = sum c dz[j].
struct MapEntry {
  int local;
  int coordinate;
  double coefficient;
};

/// The temporaries of the system-level functions (the joint tree's accelerations, derivatives and
/// geometric stiffness, the loops' and bodies' constraints, the spring-dampers, the prescribed
/// motions), kept by the caller from call to call so that a time step allocates nothing once they
/// have their sizes (the dynamic analysis keeps one in its workspace). Their contents mean nothing
/// between calls; a function given none makes its own (and allocates).
struct SystemScratch {
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  std::vector<Vec6> convective, transmitted, vel, acc;  ///< per node (joint_tree)
  /// Per node, a coordinate's derivatives of its velocity and acceleration
  /// (NodeAccelerationConfigurationDerivative).
  struct RateColumn {
    int col;
    Vec6 dvel, dacc;
  };
  std::vector<std::vector<RateColumn>> rate_columns;
  std::vector<int> cols;
  Eigen::VectorXd lambda, g, minus_f, delta;  ///< the bodies' constraints; prescribed increments
  Eigen::MatrixXd G, H;
  std::vector<MapEntry> map;  ///< a body's or a spring's map (never both at once)
  Eigen::VectorXd fv;         ///< a spring's force, stiffness and damping
  Eigen::MatrixXd Km, Cm;
};

struct SystemState {
  std::vector<Eigen::VectorXd> z;  ///< per node: accumulated coordinates (joint values)
  std::vector<NodeJacobian> J;     ///< per node, at this configuration
  std::vector<Eigen::Vector3d> x;
  std::vector<Eigen::Matrix3d> R;
  std::vector<Eigen::VectorXd> eta;   ///< per body
  std::vector<FrameSolution> frames;  ///< per body, the last solved floating frame
  Eigen::VectorXd lambda;             ///< the multipliers (DofMap::multiplier_first, body_multiplier_first)
};

/// Numbering of the unknowns (coordinates). It holds no reference to the model, so it stays
/// valid when the model it came from is moved or destroyed (SystemModel::Number, dofs()).
class DofMap {
 public:
  explicit DofMap(const SystemModel& model);
  /// True when `model` has the structure this map was made from (Shape).
  bool Matches(const SystemModel& model) const;
  int n_dofs() const { return n_dofs_; }
  /// First coordinate of node k and how many it has (6 when free; its joint's coordinates when
  /// it hangs on a joint).
  int node_first(int k) const { return node_first_[k]; }
  int node_count(int k) const { return node_count_[k]; }
  /// The joint node k hangs on (to a parent node or to the ground), or -1: a free node.
  int joint_of(int k) const { return joint_of_[k]; }
  bool free(int k) const { return joint_of_[k] < 0; }
  /// Nodes, parents before children.
  const std::vector<int>& order() const { return order_; }
  /// First coordinate of body b's modal coordinates.
  int mode_dof(int b) const { return mode_dof_[b]; }
  /// The unknowns after the coordinates: the multipliers of the cut joints' kept equations
  /// (cut joint c's from multiplier_first(c)) and of the bodies' interface constraints,
  /// n_multipliers() of them; none without loops or constrained bodies.
  int n_multipliers() const { return n_dofs_ - first_multiplier_; }
  int multiplier_first(int c) const { return multiplier_first_[c]; }
  /// After the cut joints': body b's multipliers of its interface constraint (thesis 8.2 case 4,
  /// InterfaceConstraint), n_constraints() of them; -1 when it has none.
  int body_multiplier_first(int b) const { return body_multiplier_first_[b]; }
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
  // What numbers the unknowns: nodes, joints (child, parent, coordinates), bodies (modes,
  // constraints), cut joints' equations, prescribed coordinates.
  static std::vector<int> Shape(const SystemModel& model);
  std::vector<int> shape_;
  std::vector<int> node_first_, node_count_, joint_of_, order_, mode_dof_, solved_, multiplier_first_,
      body_multiplier_first_;
  std::vector<bool> prescribed_;
  int n_dofs_ = 0, first_multiplier_ = 0;
};

/// Supports: joints of node k to the ground (parent kGround), at its initial placement. Each
/// replaces the node's support if it has one (a node hangs on one joint).
/// Node k clamped to ground (a rigid joint).
void Clamp(SystemModel& model, int k);
/// Node k's position fixed, rotation free (spherical joint to ground).
void Pin(SystemModel& model, int k);
/// Revolute joint to ground about the fixed unit axis a (global): one rotation coordinate.
void RevoluteToGround(SystemModel& model, int k, const Eigen::Vector3d& axis);
/// Prismatic joint to ground along a (global): one translation coordinate, rotation fixed.
void PrismaticToGround(SystemModel& model, int k, const Eigen::Vector3d& axis);
/// Cylindrical joint to ground: translation along and rotation about a.
void CylindricalToGround(SystemModel& model, int k, const Eigen::Vector3d& axis);
/// Any joint of node k to the ground (axes global; universal: axis2 the second axis).
void JointToGround(SystemModel& model, JointType type, int k, const Eigen::Vector3d& axis,
                   const Eigen::Vector3d& axis2 = Eigen::Vector3d::UnitY());
/// True when node k cannot move: it hangs on a joint without coordinates (rigid, clamp) on the
/// ground or on a node that cannot move either.
bool FixedToGround(const SystemModel& model, int k);

/// Adds an interface node to `model` at a position and returns its index.
int AddNode(SystemModel& model, const std::string& name, const Eigen::Vector3d& x,
            const Eigen::Matrix3d& R = Eigen::Matrix3d::Identity());

/// The initial state: nodes at their initial placement, modes at rest, frames at the bodies'
/// undeformed frames, node Jacobians computed.
SystemState InitialState(const SystemModel& model);

/// Sets the prescribed coordinates to their values at t: configuration (through the node's
/// basis), and, when W / Wdot are given, their rates and accelerations.
void ApplyPrescribed(const SystemModel& model, const DofMap& dofs, double t, SystemState& state, Eigen::VectorXd* W,
                     Eigen::VectorXd* Wdot, SystemScratch* scratch = nullptr);
/// ApplyPrescribed's increments: on each prescribed coordinate of `delta`, the step from `state`
/// to its value at t (the other entries untouched), and with W / Wdot its rate and acceleration
/// at t; for a caller that applies them with increments of its own in one ApplyIncrement.
void PrescribedIncrements(const SystemModel& model, const DofMap& dofs, double t, const SystemState& state,
                          Eigen::VectorXd& delta, Eigen::VectorXd* W, Eigen::VectorXd* Wdot);

/// The diagonal of the bounding box of points (node positions): the model's size; 0 for fewer
/// than two points.
double BoundingDiagonal(const std::vector<Eigen::Vector3d>& points);

/// The model's size, the length that every tolerance and weight in length units refers to (the
/// rotations' weight in Newton's test, the loops' violation, the step controller's scale, the
/// midpoint scheme's discrete gradients): the diagonal of the nodes' bounding box at placement;
/// with all nodes at one point (a free body held by its centre of mass), the bodies' own size
/// (SuperelementBody::length); 1 for a model with neither.
double ModelSize(const SystemModel& model);

/// Applies an increment of the unknowns: x += dx, R <- exp(dpi~) R, eta += d eta.
void ApplyIncrement(const SystemModel& model, const DofMap& dofs, const Eigen::VectorXd& delta, SystemState& state);

/// The body's configuration taken from the system state (into `c`: reusing its storage).
BodyConfiguration BodyConfigurationOf(const SystemModel& model, const SystemState& state, int body);
void BodyConfigurationOf(const SystemModel& model, const SystemState& state, int body, BodyConfiguration& c);

}  // namespace femb
