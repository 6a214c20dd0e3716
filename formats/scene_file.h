// The scene file (YAML): what femb-solve reads. Parsing checks names and ranges and names
// FILE:LINE: key on failure; the format is documented in formats/SCENE_FORMAT.md.
#pragma once

#include <Eigen/Core>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "formats/kinds.h"

namespace femb {

/// A scalar function of time (or of the pseudo-time of a static analysis).
/// The time functions of a scene (SCENE_FORMAT.md `functions`).
enum class TimeFunctionType {
  kLinear,    ///< f = slope t
  kConstant,  ///< f = value
  kRamp,      ///< 0 before t_start, value after t_end, linear between
  kStep,      ///< value from t_start on
  kPulse,     ///< value on [t_start, t_end)
  kSine,      ///< offset + amplitude sin(2 pi frequency t + phase)
  kTable,     ///< linear between (t, f) points, constant outside
  kSpinUp,    ///< smooth spin-up to the rate `value` over t_end, then constant rate
};
template <>
struct Words<TimeFunctionType> {
  static constexpr KindWord<TimeFunctionType> list[] = {
      {TimeFunctionType::kLinear, "linear"}, {TimeFunctionType::kConstant, "constant"},
      {TimeFunctionType::kRamp, "ramp"},     {TimeFunctionType::kStep, "step"},
      {TimeFunctionType::kPulse, "pulse"},   {TimeFunctionType::kSine, "sine"},
      {TimeFunctionType::kTable, "table"},   {TimeFunctionType::kSpinUp, "spin_up"}};
};

struct TimeFunctionSpec {
  TimeFunctionType type = TimeFunctionType::kLinear;
  double value = 1.0;                 ///< constant value; final value of ramp and step
  double t_start = 0.0, t_end = 1.0;  ///< ramp from 0 at t_start to value at t_end; step at t_start
  double amplitude = 0.0, frequency = 0.0, phase = 0.0, offset = 0.0;  ///< sine [Hz]
  std::vector<std::pair<double, double>> table;                        ///< (t, f) pairs, linear in between
  double Evaluate(double t) const;
  double Rate(double t) const;          ///< f'(t) (piecewise: the right derivative)
  double Acceleration(double t) const;  ///< f''(t) (kinks: 0)
  /// Times where f or its rate jumps (step, pulse, ramp ends, table points, end of a spin-up):
  /// step boundaries for error-controlled steps.
  std::vector<double> Breakpoints() const;
};

/// The probe quantities (SCENE_FORMAT.md `probes`); the analysis, integrator, bodies, joints
/// and loads are kinds of formats/kinds.h.
enum class ProbeQuantity {
  kPosition,
  kRotation,
  kVelocity,
  kAngularVelocity,
  kJoint,
  kReaction,
  kStress,
  kAcceleration,
  kAngularAcceleration,
  kDeformation,
  kEffort
};
template <>
struct Words<ProbeQuantity> {
  static constexpr KindWord<ProbeQuantity> list[] = {{ProbeQuantity::kPosition, "position"},
                                                     {ProbeQuantity::kRotation, "rotation"},
                                                     {ProbeQuantity::kVelocity, "velocity"},
                                                     {ProbeQuantity::kAngularVelocity, "angular_velocity"},
                                                     {ProbeQuantity::kJoint, "joint"},
                                                     {ProbeQuantity::kReaction, "reaction"},
                                                     {ProbeQuantity::kStress, "stress"},
                                                     {ProbeQuantity::kAcceleration, "acceleration"},
                                                     {ProbeQuantity::kAngularAcceleration, "angular_acceleration"},
                                                     {ProbeQuantity::kDeformation, "deformation"},
                                                     {ProbeQuantity::kEffort, "effort"}};
};

struct SceneBodySpec {
  std::string name;
  BodyType type = BodyType::kSuperelement;
  std::string superelement;  ///< file path (relative paths are relative to the scene file)
  // rigid: mass, centre of mass and inertia about it (part axes), attachment points (part axes)
  double mass = 0.0;
  Eigen::Vector3d center_of_mass = Eigen::Vector3d::Zero();
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
  std::map<std::string, Eigen::Vector3d> points;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d rotation = Eigen::Vector3d::Zero();  ///< rotation vector [rad]
  std::map<std::string, std::string> nodes;            ///< interface name -> scene node name
  bool approximated = false, full_tangent = true, quadratic_velocity_terms = true, option_b = false;
  bool polynomial_force = true;  ///< use the file's polynomial internal force when it has one
  /// options.geometric_stiffening: unset = use what the file has; true = require it; false = off.
  std::optional<bool> geometric_stiffening;
  /// options.inertia: unset = exact when the file has the inertia invariants; exact = require
  /// them; corotational = the thesis' kinetic energy (SuperelementOptions::exact_inertia).
  std::optional<bool> exact_inertia;
  double modal_damping = 0.0;  ///< damping ratio of the internal modes
  std::string where;
};

struct SceneJointSpec {
  JointType type = JointType::kRigid;  ///< a rigid joint without a parent is a clamp (to the ground)
  std::string node;
  std::string parent;                                ///< "" = to ground; else the node this one depends on
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();   ///< revolute/prismatic/cylindrical/universal (global)
  Eigen::Vector3d axis2 = Eigen::Vector3d::UnitY();  ///< universal: second axis (global at t = 0)
  std::string prescribed;  ///< time function of the joint coordinate (angle or travel); "" = free
  bool cut = false;        ///< close it by constraint equations even where it could be a tree joint
  std::string where;
  /// The scene file's word for the joint: `clamp` for a rigid joint to the ground.
  const char* Word() const { return type == JointType::kRigid && parent.empty() ? "clamp" : Name(type); }
};

struct SceneLoadSpec {
  LoadType type = LoadType::kForce;  ///< force and/or moment on a node, gravity, spring
  std::string node;
  Eigen::Vector3d force = Eigen::Vector3d::Zero(), moment = Eigen::Vector3d::Zero();
  bool follower = false;
  std::string function;  ///< name of a time function ("" = linear for static, constant 1 for dynamic)
  Eigen::Vector3d g = Eigen::Vector3d::Zero();
  // spring: node (end a), node_b or point (end b), stiffness, damping, free_length (< 0: initial)
  std::string node_b;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  double stiffness = 0.0, damping = 0.0, free_length = -1.0;
  std::string where;
};

struct SceneProbeSpec {
  std::string name;
  std::string node;
  /// A point probe names a body and a point instead of a node (`point`: scene coordinates at the
  /// initial placement): position, velocity, acceleration and deformation of the material point
  /// there (interpolated from the file's mesh and mode shapes), stress at the body's stress
  /// point nearest to it.
  std::string body;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  /// Node probes: position, rotation, velocity, angular_velocity, acceleration,
  /// angular_acceleration, joint, reaction, effort; point probes: position, velocity,
  /// acceleration, deformation, stress.
  std::vector<ProbeQuantity> quantities;
  std::string where;
};

/// outputs.stress_exclude: the mesh nodes left out of each body's largest von Mises stress
/// (results.h5 max_von_mises; the animation's fields keep them): those within `distance` of
/// the nodes the named interfaces' couplings tie (`interfaces`: "<body>.<interface>"; empty:
/// every interface of every body).
struct StressExcludeSpec {
  double distance = -1.0;  ///< < 0: nothing excluded
  std::vector<std::string> interfaces;
  std::string where;
};

struct SceneAnalysisSpec {
  AnalysisType type = AnalysisType::kStatic;
  int mode_count = 10;              ///< modes: how many
  bool modes_about_static = false;  ///< modes: about the static state under the loads at end_time
  double end_time = 1.0;
  int steps = 10;      ///< static: load steps over [0, end_time]
  double step = 1e-3;  ///< dynamic: time step (unused with step: auto)
  /// dynamic, `step: auto`: error-controlled steps (solver/analysis/dynamic_analysis.h,
  /// DynamicOptions): the local error of the positions relative to the model's motion below
  /// step_tolerance, steps within [min_step, max_step] (0: defaults from end_time), results
  /// at every output_step (0: at every step taken).
  bool adaptive_step = false;
  double step_tolerance = 1e-5;
  double min_step = 0.0, max_step = 0.0, output_step = 0.0;
  double rho_inf = 0.9;
  /// dynamic: generalized_alpha (numerical damping by rho_inf) or midpoint (momentum-conserving,
  /// no damping; solver/analysis/dynamic_analysis.h)
  Integrator integrator = Integrator::kGeneralizedAlpha;
  double tolerance = 1e-8;
  int max_iterations = 25;
  int output_every = 1;
  std::optional<JacobianReuse>
      jacobian_reuse;  ///< dynamic: which Newton iterations factor anew (unset: the integrator's)
  bool gyroscopic_tangent =
      false;  ///< generalized-alpha: configuration derivative of the quadratic velocity terms in S
  int body_matrices_every =
      0;  ///< generalized-alpha: bodies' matrices computed every n-th step (0: unset, the solver's default)
  BodyMatricesKept body_matrices_kept = BodyMatricesKept::kAll;  ///< which of them body_matrices_every keeps
};

struct SceneSpec {
  std::string file;
  std::string name;
  std::string units = "SI";
  std::vector<SceneBodySpec> bodies;
  std::vector<SceneJointSpec> joints;
  std::vector<SceneLoadSpec> loads;
  std::map<std::string, TimeFunctionSpec> functions;
  SceneAnalysisSpec analysis;
  std::vector<SceneProbeSpec> probes;
  bool animation = true;  ///< write animation.xdmf/.h5 when the superelement files hold meshes
  /// One animation frame per this many output steps; 0 (default): about 500 frames per run
  /// (ResultsRecorder; every output step up to 500 of them).
  int animation_every = 0;
  /// Compute the support and joint reactions at every output step (outputs.reactions, or a probe
  /// asking for `reaction`): /nodes/reaction in results.h5.
  bool reactions = false;
  /// Stress recovery in every body whose superelement file has modal stresses (outputs.stresses):
  /// the von Mises stress as a node field of the animation, and each body's largest von Mises
  /// stress and where it is per output step in results.h5. Off by default (no cost); stress
  /// probes work without it.
  bool stresses = false;
  /// With stresses: the largest and smallest principal stress as node fields of the animation
  /// too (outputs.principal_stresses; they cost about as much again as the von Mises field).
  bool principal_stresses = false;
  StressExcludeSpec stress_exclude;
  /// Results written during the run (outputs.flush_every, seconds of wall time; 0: at every
  /// output step) and every this many output steps (outputs.flush_every_steps; 0: off).
  double flush_every = 10.0;
  long flush_every_steps = 0;
  /// initial_state: start from the state another run reached (its folder's checkpoint.h5; a
  /// relative folder is relative to the scene file's), at `time` (unset: a dynamic run's state
  /// at its own time, a static one's at 0).
  struct InitialStateSpec {
    std::string from, where;
    std::optional<double> time;
  } initial_state;
  /// Initial velocity (spatial) of named nodes: (linear, angular).
  std::map<std::string, std::pair<Eigen::Vector3d, Eigen::Vector3d>> initial_velocities;
  /// Initial joint rates of named nodes that have a joint (revolute: angular rate, ...).
  std::map<std::string, std::vector<double>> initial_joint_rates;
};

/// Reads a scene file with "key.path=value" overrides applied first. Throws InputError naming
/// FILE:LINE and the key.
SceneSpec ReadSceneFile(const std::string& path, const std::vector<std::string>& overrides = {});
SceneSpec ParseScene(const std::string& text, const std::string& name, const std::vector<std::string>& overrides = {});

}  // namespace femb
