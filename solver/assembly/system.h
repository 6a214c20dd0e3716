// A multibody system of superelements on shared 6-DOF nodes, without Lagrange multipliers.
// Nodes shared by bodies are rigid connections; grounded nodes are removed from the unknowns.
// Unknowns: (dx, dpi) of every free node (spatial increments), then the modal coordinates of
// every body. Model (immutable) and State are separate: f(const Model&, State&).
#pragma once

#include <Eigen/Core>
#include <array>
#include <functional>
#include <string>
#include <vector>

#include "solver/body/superelement_body.h"
#include "solver/forces/spring_damper.h"

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
  /// Per node: which of its 6 components (x, y, z, rx, ry, rz; spatial) are held fixed. All six:
  /// clamped to ground; the first three: spherical joint to ground.
  std::vector<std::array<bool, 6>> fixed;
  std::vector<SuperelementBody> bodies;
  std::vector<std::vector<int>> body_nodes;  ///< system node of each interface of each body
  std::vector<NodeLoad> loads;
  std::vector<SpringDamper> springs;
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();  ///< uniform acceleration field (dynamic analyses)

  int n_nodes() const { return int(node_names.size()); }
};

struct SystemState {
  std::vector<Eigen::Vector3d> x;
  std::vector<Eigen::Matrix3d> R;
  std::vector<Eigen::VectorXd> eta;         ///< per body
  std::vector<FrameSolution> frames;        ///< per body, the last solved floating frame
};

/// Numbering of the unknowns.
class DofMap {
 public:
  explicit DofMap(const SystemModel& model);
  int n_dofs() const { return n_dofs_; }
  /// Unknown of component i (0-5) of node k, or -1 when that component is fixed.
  int node_dof(int k, int i) const { return node_dof_[6 * k + i]; }
  /// First unknown of body b's modal coordinates.
  int mode_dof(int b) const { return mode_dof_[b]; }

 private:
  std::vector<int> node_dof_, mode_dof_;
  int n_dofs_ = 0;
};

/// Holds all 6 components of node k fixed (clamp to ground).
inline void Clamp(SystemModel& model, int k) { model.fixed[k].fill(true); }
/// Holds node k's position fixed, rotation free (spherical joint to ground).
inline void Pin(SystemModel& model, int k) { model.fixed[k] = {true, true, true, false, false, false}; }

/// Adds an interface node to `model` at a position and returns its index.
int AddNode(SystemModel& model, const std::string& name, const Eigen::Vector3d& x,
            const Eigen::Matrix3d& R = Eigen::Matrix3d::Identity());

/// The initial state: nodes at their initial placement, modes at rest, frames at the bodies'
/// undeformed frames.
SystemState InitialState(const SystemModel& model);

/// Result of an evaluation of internal and external forces.
struct SystemForces {
  bool ok = true;
  std::string message;            ///< what failed (a floating frame did not converge, ...)
  Eigen::VectorXd residual;       ///< lambda f_ext - f_int over the unknowns
  Eigen::MatrixXd tangent;        ///< d(f_int - lambda f_ext)/d(unknowns)
  double elastic_energy = 0.0;
  double force_scale = 0.0;       ///< largest norm of the internal or external force terms
};

/// Solves every body's floating frame (updating state.frames) and assembles the static
/// residual and tangent at load factor `lambda`.
SystemForces AssembleStatic(const SystemModel& model, const DofMap& dofs, SystemState& state, double lambda,
                            bool with_tangent);

/// External nodal loads at time t (or load factor) and their stiffness d(-f_ext)/dq added to
/// `tangent` when not null (follower loads).
void AddNodeLoads(const SystemModel& model, const DofMap& dofs, const SystemState& state, double t,
                  Eigen::VectorXd& residual, Eigen::MatrixXd* tangent);

/// Spring-damper forces added to `residual` (as applied forces), their stiffness and damping
/// (of -f) to `K`, `C` when not null, their energy to `energy`. W may be empty (static).
void AddSpringDampers(const SystemModel& model, const DofMap& dofs, const SystemState& state, const Eigen::VectorXd& W,
                      Eigen::VectorXd& residual, Eigen::MatrixXd* K, Eigen::MatrixXd* C, double* energy);

/// Gathers body b's velocities (xdot, omega per interface node, then etadot) from system
/// velocities W over the unknowns (grounded nodes: zero).
Eigen::VectorXd GatherBody(const SystemModel& model, const DofMap& dofs, int b, const Eigen::VectorXd& W);

/// For each local coordinate of body b the system unknown, or -1 (grounded).
std::vector<int> BodyDofMap(const SystemModel& model, const DofMap& dofs, int b);

/// Applies an increment of the unknowns: x += dx, R <- exp(dpi~) R, eta += d eta.
void ApplyIncrement(const SystemModel& model, const DofMap& dofs, const Eigen::VectorXd& delta, SystemState& state);

/// The body's configuration taken from the system state.
BodyConfiguration BodyConfigurationOf(const SystemModel& model, const SystemState& state, int body);

}  // namespace femb
