#include "solver/scene/scene_builder.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

#include "formats/input_error.h"
#include "formats/part_file.h"
#include "formats/solid_shape.h"
#include "formats/superelement_checks.h"
#include "formats/superelement_file.h"
#include "solver/joints/loop_constraints.h"
#include "solver/rotation.h"
#include "solver/scene/scene_outputs.h"

namespace femb {

namespace {

// Node k's first joint coordinate follows the time function f (value, rate, acceleration).
SystemModel::Prescribed PrescribedBy(const TimeFunctionSpec& f, int k) {
  SystemModel::Prescribed p;
  p.node = k;
  p.coordinate = 0;
  p.value = [f](double t) { return f.Evaluate(t); };
  p.rate = [f](double t) { return f.Rate(t); };
  p.acceleration = [f](double t) { return f.Acceleration(t); };
  return p;
}
// Joints that share a point (spherical, revolute, universal; cylindrical up to a shift along its
// axis) refuse nodes that are apart at t = 0: the offset would silently become a rigid arm of
// the parent (node_joint.h: x_c = x_p + R_p r0). Tolerance 1e-6 of the scene's size.
void RequireJointGap(const SceneJointSpec& j, const Eigen::Vector3d& x_p, const Eigen::Vector3d& x_c,
                     double scene_length) {
  Eigen::Vector3d gap = x_c - x_p;
  const bool cylindrical = j.type == JointType::kCylindrical;
  if (cylindrical) gap -= gap.dot(j.axis.normalized()) * j.axis.normalized();
  if (j.type != JointType::kSpherical && j.type != JointType::kRevolute && j.type != JointType::kUniversal &&
      !cylindrical) {
    return;
  }
  const double tolerance = 1e-6 * std::max(scene_length, 1e-3 * std::max(x_p.norm(), x_c.norm()));
  if (gap.norm() <= tolerance) return;
  char buffer[400];
  std::snprintf(buffer, sizeof buffer,
                ": %s joint between nodes '%s' and '%s': the nodes are %.6g apart at t = 0 (gap (%.6g, %.6g, %.6g)%s); "
                "a %s joint needs them at one point: move the bodies or use a rigid joint for an offset",
                j.Word(), j.node.c_str(), j.parent.c_str(), gap.norm(), gap.x(), gap.y(), gap.z(),
                cylindrical ? " across the axis" : "", j.Word());
  throw InputError(j.where + buffer);
}

}  // namespace

namespace {

// A drive whose function is not 0 at t = 0 moves its joint away from the placement at the start.
// Along a tree the rest follows; in a closed loop the mechanism would have to be assembled anew
// there, which Newton's first step cannot do from the placement (it stopped with "Newton
// diverged at t = 0"): refused with the joint, its start value and the gap it opens.
void RequireLoopsClosedAtStart(const SceneSpec& spec, const SystemModel& model, const DofMap& dofs) {
  if (model.cut_joints.empty()) return;
  std::string moved;
  for (const SystemModel::Prescribed& p : model.prescribed) {
    const double start = p.value(0.0);
    if (start == 0.0) continue;
    for (const SceneJointSpec& j : spec.joints) {
      if (j.node == model.node_names[size_t(p.node)] && !j.prescribed.empty()) {
        char buffer[300];
        std::snprintf(buffer, sizeof buffer, "%s: prescribed '%s' of node '%s' is %.6g at t = 0", j.where.c_str(),
                      j.prescribed.c_str(), j.node.c_str(), start);
        moved += std::string(moved.empty() ? "" : "; ") + buffer;
      }
    }
  }
  if (moved.empty()) return;
  SystemState state = InitialState(model);
  ApplyPrescribed(model, dofs, 0.0, state, nullptr, nullptr);
  int worst = -1;
  const double gap = LoopViolation(model, state, &worst);
  if (gap <= 1e-9 * ModelSize(model)) return;
  char buffer[200];
  std::snprintf(buffer, sizeof buffer, ", which opens the loop closed by %s by %.3g at the start",
                worst >= 0 && size_t(worst) < model.cut_joints.size() ? model.cut_joints[size_t(worst)].name.c_str()
                                                                      : "a cut joint",
                gap);
  throw InputError(moved + buffer +
                   " (the scene places the mechanism at 0): place the bodies at the drive's start "
                   "position, or give the function an offset so that it is 0 at t = 0");
}

// Where the bodies put the scene's nodes (node -> position, by which body) and the rigid bodies'
// points (child node, centre-of-mass node), for the joint tree.
struct Placement {
  std::map<std::string, std::pair<Eigen::Vector3d, std::string>> placed;
  std::vector<std::pair<int, int>> rigid_attachments;
};

// A rigid body: one node at the centre of mass carrying the 6 x 6 rigid mass, no stiffness; its
// attachment points are rigid offsets (dependent nodes) of that node. `b` placed relative to the
// scene's origin.
void AddRigidBody(const SceneBodySpec& b, Scene& scene, Placement& placement) {
  SystemModel& model = scene.model;
  auto& placed = placement.placed;
  const Eigen::Matrix3d R = ExpSO3(b.rotation);
  const std::string com_node = b.nodes.at("com");
  if (scene.node_index.count(com_node)) {
    throw InputError(b.where + ": rigid body '" + b.name + "': its centre-of-mass node '" + com_node +
                     "' is already used by another body");
  }
  const int com = AddNode(model, com_node, b.position + R * b.center_of_mass, R);
  scene.node_index[com_node] = com;
  placed[com_node] = {model.node_x0[com], b.name};
  model.bodies.push_back(SuperelementBody::Rigid({b.mass, b.center_of_mass, b.inertia}, R, b.position));
  model.body_nodes.push_back({com});
  scene.body_names.push_back(b.name);
  model.body_names.push_back(b.name);
  scene.meshes.emplace_back();
  scene.stresses.emplace_back();
  scene.mesh_origin.push_back(b.center_of_mass);
  scene.interface_names.push_back({"com"});
  scene.interface_points.push_back({b.center_of_mass});
  scene.stick_nodes.push_back({com});
  for (const auto& [point, node] : b.nodes) {
    if (point == "com") continue;
    const Eigen::Vector3d x = b.position + R * b.points.at(point);
    auto found = scene.node_index.find(node);
    int k;
    if (found == scene.node_index.end()) {
      k = AddNode(model, node, x, R);
      scene.node_index[node] = k;
      placed[node] = {x, b.name};
    } else {
      k = found->second;
      if ((model.node_x0[k] - x).norm() > 1e-9 * std::max(1.0, x.norm())) {
        throw InputError(b.where + ": rigid body '" + b.name + "': point '" + point +
                         "' at a different place than node '" + node + "' of body '" + placed[node].second + "'");
      }
    }
    placement.rigid_attachments.emplace_back(k, com);
    scene.stick_nodes.back().push_back(k);
  }
}

// A superelement body's file (its path, resolved against the scene's folder, into `file`), with the stresses and
// the mesh when the scene's outputs need them, checked.
Superelement ReadBodyFile(const SceneSpec& spec, const SceneBodySpec& b, std::filesystem::path& file) {
  const std::filesystem::path base = std::filesystem::path(spec.file).parent_path();
  file = b.superelement;
  if (file.is_relative()) file = base / file;
  Superelement se;
  try {
    SuperelementReadOptions options;
    bool stress_probe = false, point_probe = false;
    for (const SceneProbeSpec& p : spec.probes) {
      if (p.body != b.name) continue;
      point_probe = true;
      stress_probe |= std::count(p.quantities.begin(), p.quantities.end(), ProbeQuantity::kStress) > 0;
    }
    options.stress = spec.stresses || stress_probe;
    options.visualization = spec.animation || options.stress || point_probe;
    se = ReadSuperelementFile(file.string(), options);
    RequireValidSuperelement(se, file.string());
  } catch (const InputError& e) {
    throw InputError(b.where + ": body '" + b.name + "': " + e.what());
  }
  if (se.units.system != spec.units) {
    throw InputError(b.where + ": body '" + b.name + "': superelement units " + se.units.system +
                     " differ from the scene's " + spec.units);
  }
  return se;
}

// A superelement body's formulation: the scene's options against what the file holds (an option
// asked for that the file cannot give is an error; one it lacks by default, a note).
SuperelementOptions BodyOptions(const SceneSpec& spec, const SceneBodySpec& b, const Superelement& se,
                                const std::filesystem::path& file, std::vector<std::string>& notes) {
  SuperelementOptions options;
  options.approximated = b.approximated;
  options.full_tangent = b.full_tangent;
  options.quadratic_velocity_terms = b.quadratic_velocity_terms;
  options.cardona_option_b = b.option_b;
  options.polynomial_force = b.polynomial_force;
  options.modal_damping = b.modal_damping;
  // Geometric stiffening: what the file has, unless switched off; asked for
  // explicitly from a file without it is an error, otherwise a note. The midpoint integrator
  // conserves the energy of linear bodies with the corotational inertia (thesis 3.22) exactly;
  // its elastic force is no exact discrete gradient of the stiffened energy, and the
  // corotational inertia gives wrong Southwell slopes with the stiffening (README), so there it
  // is used only when asked for.
  const bool midpoint = spec.analysis.integrator == Integrator::kMidpoint;
  options.geometric_stiffening = b.geometric_stiffening.value_or(!midpoint);
  const bool file_has_stiffening = !se.inertia_stiffness.empty();
  if (b.geometric_stiffening.value_or(false) && !file_has_stiffening) {
    throw InputError(b.where + ": body '" + b.name + "': options.geometric_stiffening is true but " + file.string() +
                     " has no geometric stiffening (reduce it with reduction.geometric_stiffening: true)");
  }
  const bool imported = se.provenance.element_type.rfind("imported", 0) == 0;
  if (!b.geometric_stiffening.has_value() && !file_has_stiffening && se.n_reduced_dofs() > 6) {
    // What a linear body costs: in a rotating part the centrifugal stiffening of its bending
    // (rotating_beam example: one body without it 43-59% off, with it 2.2%). With modal
    // derivatives the body is not linear inside: their cubic force stiffens it as far as their
    // shapes represent the loads' deformation.
    const std::string inside =
        se.polynomial ? "is nonlinear inside through its modal derivatives' cubic force alone, so a rotating or highly "
                        "loaded part keeps of its stress stiffening only what those shapes represent"
                      : "is linear inside, so a rotating or highly loaded part misses its stress stiffening";
    notes.push_back("body '" + b.name + "': " + file.string() + " has no geometric stiffening; the body " + inside +
                    " (" +
                    (imported ? "an imported part of solid cells gets it from the part's material:, others "
                                "can be split into several bodies"
                              : "re-reduce it with reduction.geometric_stiffening: true to add it") +
                    ")");
  }
  // The exact kinetic energy: the file's inertia invariants unless switched off, with either
  // integrator (the midpoint scheme takes its momenta and source, MomentumSource).
  options.exact_inertia = b.exact_inertia.value_or(true);
  if (b.exact_inertia.value_or(false) && se.inertia_gamma.empty()) {
    throw InputError(b.where + ": body '" + b.name + "': options.inertia is exact but " + file.string() +
                     " has no inertia invariants (an older femb-reduce wrote it: reduce the part again, "
                     "femb-reduce stores them for every part)");
  }
  if (!b.exact_inertia.has_value() && se.inertia_gamma.empty() && se.n_reduced_dofs() > 6) {
    notes.push_back("body '" + b.name + "': " + file.string() +
                    " has no inertia invariants (an older "
                    "femb-reduce wrote it): the corotational inertia (thesis 3.22) approximates the "
                    "centrifugal and Coriolis coupling of the deformation (a spinning bar stretched 21% too "
                    "much); reduce the part again for the exact inertia");
  }
  if (midpoint && file_has_stiffening && !b.geometric_stiffening.has_value()) {
    notes.push_back("body '" + b.name +
                    "': the midpoint integrator keeps the body linear inside, whose energy it "
                    "conserves exactly: the file's geometric stiffening is not used (generalized_alpha uses it; "
                    "options.geometric_stiffening: true forces it)");
  }
  return options;
}

// The scene nodes of a superelement body's interfaces (every interface mapped, every mapped name
// an interface), placed by the body or checked against where another body put them.
std::vector<int> PlaceInterfaces(const SceneBodySpec& b, const Superelement& se, const std::filesystem::path& file,
                                 const Eigen::Matrix3d& R, Scene& scene, Placement& placement) {
  SystemModel& model = scene.model;
  auto& placed = placement.placed;
  std::vector<int> nodes;
  for (const auto& [iname, _] : b.nodes) {
    bool found = false;
    for (const auto& i : se.interfaces) found |= i.name == iname;
    if (!found) {
      std::string known;
      for (const auto& i : se.interfaces) known += (known.empty() ? "" : ", ") + i.name;
      throw InputError(b.where + ": body '" + b.name + "': " + file.string() + " has no interface '" + iname +
                       "' (it has: " + known + ")");
    }
  }
  for (const InterfaceNode& interface : se.interfaces) {
    auto it = b.nodes.find(interface.name);
    if (it == b.nodes.end()) {
      throw InputError(b.where + ": body '" + b.name + "': interface '" + interface.name +
                       "' is not mapped to a scene node under 'nodes'");
    }
    const std::string& node = it->second;
    const Eigen::Vector3d x = b.position + R * interface.position;
    auto found = scene.node_index.find(node);
    if (found == scene.node_index.end()) {
      scene.node_index[node] = AddNode(model, node, x, R * interface.orientation);
      placed[node] = {x, b.name};
    } else {
      const auto& [x_other, other] = placed[node];
      if ((x - x_other).norm() > 1e-9 * std::max(1.0, x.norm())) {
        char buffer[300];
        const Eigen::Vector3d xa = x + scene.origin, xb = x_other + scene.origin;
        std::snprintf(buffer, sizeof buffer,
                      "node '%s' is placed at (%.6g, %.6g, %.6g) by body '%s' but at (%.6g, %.6g, %.6g) by body '%s'",
                      node.c_str(), xa.x(), xa.y(), xa.z(), b.name.c_str(), xb.x(), xb.y(), xb.z(), other.c_str());
        throw InputError(b.where + ": " + buffer);
      }
    }
    nodes.push_back(scene.node_index[node]);
  }
  return nodes;
}

// A superelement body from its file. `b` placed relative to the scene's origin.
void AddSuperelementBody(const SceneSpec& spec, const SceneBodySpec& b, Scene& scene, Placement& placement) {
  SystemModel& model = scene.model;
  std::filesystem::path file;
  Superelement se = ReadBodyFile(spec, b, file);
  const Eigen::Matrix3d R = ExpSO3(b.rotation);
  const SuperelementOptions options = BodyOptions(spec, b, se, file, scene.notes);
  const std::vector<int> nodes = PlaceInterfaces(b, se, file, R, scene, placement);
  scene.stresses.push_back(std::move(se.stress));
  se.stress.reset();
  model.bodies.emplace_back(se, options, R, b.position);
  model.body_nodes.push_back(nodes);
  scene.body_names.push_back(b.name);
  model.body_names.push_back(b.name);
  scene.meshes.push_back(se.visualization);
  scene.mesh_origin.push_back(se.floating_frame.origin);
  scene.interface_names.emplace_back();
  scene.interface_points.emplace_back();
  for (const InterfaceNode& node : se.interfaces) {
    scene.interface_names.back().push_back(node.name);
    scene.interface_points.back().push_back(node.position);
  }
  scene.stick_nodes.push_back(se.visualization ? std::vector<int>() : nodes);
}

// The joint tree. Every node has at most one holder: a parent node or the ground (kGround), which
// it hangs on through a tree joint. The rigid bodies' offsets and then the scene's joints --
// prescribed ones first, then in the scene's order -- go into the tree while they can; a joint
// that would give its node a second holder or close a cycle is cut: imposed by constraint
// equations with Lagrange multipliers, its node keeping its own coordinates
// (solver/joints/loop_closure.h). `cut: true` cuts a joint on purpose.
class JointTreeBuilder {
 public:
  explicit JointTreeBuilder(SystemModel& model) : model_(model), holder_(size_t(model.n_nodes()), kNoHolder) {}
  /// Whether node k may hang on p in the tree (k has no holder and p does not hang on k).
  bool Free(int k, int p) const { return holder_[size_t(k)] == kNoHolder && !IsAncestor(k, p); }
  /// k's holder, kNoHolder if none.
  int holder(int k) const { return holder_[size_t(k)]; }
  void AddTree(JointType type, int k, int p, const Eigen::Vector3d& axis, const Eigen::Vector3d& axis2) {
    if (p == kGround) {
      JointToGround(model_, type, k, axis, axis2);
    } else {
      model_.joints.push_back(MakeNodeJoint(type, k, p, axis, model_.node_x0[p], model_.node_R0[p], model_.node_x0[k],
                                            model_.node_R0[k], axis2));
    }
    holder_[size_t(k)] = p;
  }
  void AddCut(JointType type, int k, int p, const Eigen::Vector3d& axis, const Eigen::Vector3d& axis2,
              const std::string& name) {
    CutJoint cut;
    cut.joint = MakeNodeJoint(type, k, p, axis, model_.node_x0[p], model_.node_R0[p], model_.node_x0[k],
                              model_.node_R0[k], axis2);
    cut.name = name;
    for (int i = 0; i < ConstraintCount(type); ++i) cut.equations.push_back(i);
    model_.cut_joints.push_back(cut);
  }
  /// A clamped node at node k, world axes: the parent of a cut joint to the ground.
  int HiddenGround(int k) {
    const int g = AddNode(model_, model_.node_names[k] + ".ground", model_.node_x0[k], Eigen::Matrix3d::Identity());
    Clamp(model_, g);
    holder_.push_back(kGround);
    return g;
  }
  static constexpr int kNoHolder = -2;

 private:
  bool IsAncestor(int k, int m) const {  // k on m's chain of holders (m itself included)
    for (; m >= 0; m = holder_[size_t(m)])
      if (m == k) return true;
    return false;
  }
  SystemModel& model_;
  std::vector<int> holder_;
};

// The rigid bodies' offsets into the tree: the tree of one body is rooted at its first point, in
// that order, that carries a joint not cut on purpose (a pendulum's pivot), so that the joint acts
// on the root; else at its centre of mass.
void AddRigidOffsets(const std::vector<const SceneJointSpec*>& order, const Placement& placement, Scene& scene,
                     JointTreeBuilder& tree) {
  const SystemModel& model = scene.model;
  std::map<int, int> root_of;  // COM node -> root node
  for (const SceneJointSpec* j : order) {
    if (j->cut) continue;
    const int k = scene.node_index.at(j->node);
    for (const auto& [point, com] : placement.rigid_attachments)
      if ((point == k || com == k) && !root_of.count(com)) root_of[com] = k;
  }
  for (const auto& [k, com] : placement.rigid_attachments) {
    const bool rooted_here = root_of.count(com) && root_of[com] == k;
    const int child = rooted_here ? com : k, parent = rooted_here ? k : com;
    if (!tree.Free(child, parent)) {
      tree.AddCut(
          JointType::kRigid, child, parent, Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY(),
          "rigid offset of node '" + model.node_names[k] + "' on the body at node '" + model.node_names[com] + "'");
      continue;
    }
    tree.AddTree(JointType::kRigid, child, parent, Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY());
  }
}

// The scene's joints into the tree, or cut where they close a loop; prescribed ones drive their
// tree coordinate.
void AddJoints(const SceneSpec& spec, const Placement& placement, Scene& scene) {
  SystemModel& model = scene.model;
  std::vector<const SceneJointSpec*> order;
  for (const SceneJointSpec& j : spec.joints)
    if (!j.prescribed.empty()) order.push_back(&j);
  for (const SceneJointSpec& j : spec.joints)
    if (j.prescribed.empty() && !j.cut) order.push_back(&j);
  for (const SceneJointSpec& j : spec.joints)
    if (j.cut) order.push_back(&j);
  JointTreeBuilder tree(model);
  AddRigidOffsets(order, placement, scene, tree);
  // The bounding box diagonal of the nodes: the scale of position tolerances.
  const double scene_length = ModelSize(model);
  for (const SceneJointSpec* jp : order) {
    const SceneJointSpec& j = *jp;
    const int k = scene.node_index.at(j.node);
    const int p = j.parent.empty() ? kGround : scene.node_index.at(j.parent);
    if (p >= 0) RequireJointGap(j, model.node_x0[p], model.node_x0[k], scene_length);
    const bool in_tree = !j.cut && tree.Free(k, p);
    const JointType type = j.type;
    if (!in_tree) {
      if (!j.prescribed.empty()) {
        throw InputError(
            j.where + ": " + j.Word() + " joint of node '" + j.node + "' is prescribed but closes a loop (node '" +
            j.node + "' already hangs on " +
            (tree.holder(k) >= 0 ? "node '" + model.node_names[tree.holder(k)] + "'" : std::string("the ground")) +
            "); a drive must be a tree joint: swap 'node' and 'parent', or prescribe another joint of the loop");
      }
      const std::string name = j.where + ": " + j.Word() + " joint of node '" + j.node + "'" +
                               (p >= 0 ? " on node '" + j.parent + "'" : std::string(" to the ground"));
      tree.AddCut(type, k, p >= 0 ? p : tree.HiddenGround(k), j.axis, j.axis2, name);
      continue;
    }
    tree.AddTree(type, k, p, j.axis, j.axis2);  // to a node or to the ground alike
    if (!j.prescribed.empty()) model.prescribed.push_back(PrescribedBy(spec.functions.at(j.prescribed), k));
  }
}

// An over-constrained loop (a planar four-bar of spatial revolute joints) has equations that
// repeat others: they are dropped, and a note per cut joint says what it keeps.
void NoteCutJoints(Scene& scene) {
  SystemModel& model = scene.model;
  const std::vector<std::string> dropped = DropRedundantEquations(model);
  for (size_t c = 0; c < model.cut_joints.size(); ++c) {
    const CutJoint& cut = model.cut_joints[c];
    const int all = ConstraintCount(cut.joint.type), kept = int(cut.equations.size());
    std::string note = cut.name + " closes a loop: ";
    if (kept == 0) {
      note +=
          "the other joints already hold it; its " + std::to_string(all) + " equations repeat theirs and are dropped";
    } else {
      note += std::to_string(kept) + " constraint equations with Lagrange multipliers";
      if (kept < all) {
        note += "; " + std::to_string(all - kept) + " more (" + dropped[c] +
                ") repeat other constraints (an over-constrained loop, e.g. planar links on spatial joints) and are "
                "dropped: the reactions along them are not unique";
      }
    }
    scene.notes.push_back(note);
  }
}

// The scene's loads: gravity, springs, forces and moments at nodes.
void AddLoads(const SceneSpec& spec, Scene& scene) {
  SystemModel& model = scene.model;
  for (const SceneLoadSpec& l : spec.loads) {
    if (l.type == LoadType::kGravity) {
      model.gravity += l.g;
      if (spec.analysis.type != AnalysisType::kDynamic) model.static_gravity_end = spec.analysis.end_time;
      continue;
    }
    if (l.type == LoadType::kSpring) {
      SpringDamper s;
      s.node_a = scene.node_index.at(l.node);
      s.node_b = l.node_b.empty() ? -1 : scene.node_index.at(l.node_b);
      s.ground = l.point - scene.origin;
      s.stiffness = l.stiffness;
      s.damping = l.damping;
      const Eigen::Vector3d xb = s.node_b >= 0 ? model.node_x0[s.node_b] : s.ground;
      const double initial = (xb - model.node_x0[s.node_a]).norm();
      if (initial == 0.0) throw InputError(l.where + ": spring ends coincide: its direction is undefined");
      s.free_length = l.free_length >= 0 ? l.free_length : initial;
      model.springs.push_back(s);
      continue;
    }
    const int k = scene.node_index.at(l.node);
    if (FixedToGround(model, k))
      throw InputError(l.where + ": load on node '" + l.node + "', which is clamped to the ground");
    NodeLoad load;
    load.node = k;
    load.force = l.force;
    load.moment = l.moment;
    load.follower = l.follower;
    if (!l.function.empty()) {
      const TimeFunctionSpec f = spec.functions.at(l.function);
      load.scale = [f](double t) { return f.Evaluate(t); };
    } else if (spec.analysis.type == AnalysisType::kDynamic) {
      load.scale = [](double) { return 1.0; };
    }
    model.loads.push_back(load);
  }
}

// The initial velocities over the unknowns: a free node's own, least squares on the motions of a
// node's joint to the ground, or joint rates.
void InitialVelocity(const SceneSpec& spec, const DofMap& dofs, Scene& scene) {
  const SystemModel& model = scene.model;
  scene.initial_velocity = Eigen::VectorXd::Zero(dofs.n_dofs());
  for (const auto& [node, v] : spec.initial_velocities) {
    const int k = scene.node_index.at(node);
    const int j = dofs.joint_of(k);
    if (j >= 0 && model.joints[size_t(j)].parent != kGround) {
      throw InputError(spec.file + ": initial_velocity: node '" + node +
                       "' depends on a parent through a joint; give the velocity of its parent");
    }
    if (dofs.node_count(k) == 0) continue;
    Eigen::Matrix<double, 6, 1> v6;
    v6 << v.first, v.second;
    if (j < 0) {  // a free node: its own spatial velocity
      scene.initial_velocity.segment<6>(dofs.node_first(k)) = v6;
      continue;
    }
    // On a joint to the ground: least squares on the joint's motions B (exact when the velocity
    // is admissible).
    const NodeJoint& joint = model.joints[size_t(j)];
    const JointColumns B = ComputeJointMaps(joint, Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity(),
                                            model.node_x0[k], Eigen::VectorXd::Zero(joint.n_coordinates()))
                               .B;
    scene.initial_velocity.segment(dofs.node_first(k), dofs.node_count(k)) = B.colPivHouseholderQr().solve(v6);
  }
  for (const auto& [node, rates] : spec.initial_joint_rates) {
    const int k = scene.node_index.at(node);
    const int j = dofs.joint_of(k);
    // A pin (spherical to the ground) has rotation increments, not joint coordinates: it takes
    // an angular velocity; a clamp has none.
    const bool support_without_rates =
        j >= 0 && model.joints[size_t(j)].parent == kGround &&
        (model.joints[size_t(j)].type == JointType::kSpherical || model.joints[size_t(j)].type == JointType::kRigid);
    const bool has_joint = j >= 0 && !support_without_rates;
    if (!has_joint || int(rates.size()) != dofs.node_count(k)) {
      throw InputError(
          spec.file + ": initial_velocity: node '" + node + "' has " +
          (has_joint ? std::to_string(dofs.node_count(k)) + " joint coordinates" : std::string("no joint")) + ", got " +
          std::to_string(rates.size()) + " joint rates");
    }
    for (size_t i = 0; i < rates.size(); ++i) scene.initial_velocity[dofs.node_first(k) + int(i)] = rates[i];
  }
}

}  // namespace

Scene BuildScene(const SceneSpec& spec) {
  Scene scene;
  scene.spec = spec;
  Placement placement;
  for (const SceneBodySpec& b : spec.bodies) scene.origin += b.position / double(spec.bodies.size());
  for (const SceneBodySpec& b_spec : spec.bodies) {
    SceneBodySpec b = b_spec;
    b.position -= scene.origin;
    if (b.type == BodyType::kRigid) {
      AddRigidBody(b, scene, placement);
    } else {
      AddSuperelementBody(spec, b, scene, placement);
    }
  }
  AddJoints(spec, placement, scene);
  NoteCutJoints(scene);
  // The joint graph (cycles, two parents) before anything walks it: numbering checks it.
  try {
    scene.model.Number();
  } catch (const InputError& e) {
    throw InputError(spec.file + ": joints: " + e.what());
  }
  const DofMap& dofs = scene.model.dofs();
  RequireLoopsClosedAtStart(spec, scene.model, dofs);
  AddLoads(spec, scene);
  InitialVelocity(spec, dofs, scene);
  ResolveProbes(spec, scene);
  ResolveStressExclusion(spec, scene);
  return scene;
}

}  // namespace femb
