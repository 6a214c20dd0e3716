#include "solver/scene/scene_builder.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>

#include "formats/input_error.h"
#include "formats/part_file.h"
#include "formats/solid_shape.h"
#include "formats/superelement_checks.h"
#include "formats/superelement_file.h"
#include "solver/joints/loop_constraints.h"
#include "solver/rotation.h"

namespace femb {

namespace {
Units UnitSystemOf(const std::string& name) { return UnitSystem(name, "units"); }

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
// The solver's joint for a scene joint (a clamp between two nodes is a rigid joint).
JointType SolverJointType(SceneJointType type) {
  switch (type) {
    case SceneJointType::kClamp:
    case SceneJointType::kRigid:
      return JointType::kRigid;
    case SceneJointType::kSpherical:
      return JointType::kSpherical;
    case SceneJointType::kRevolute:
      return JointType::kRevolute;
    case SceneJointType::kPrismatic:
      return JointType::kPrismatic;
    case SceneJointType::kCylindrical:
      return JointType::kCylindrical;
    case SceneJointType::kUniversal:
      return JointType::kUniversal;
  }
  return JointType::kRigid;
}

void RequireJointGap(const SceneJointSpec& j, const Eigen::Vector3d& x_p, const Eigen::Vector3d& x_c,
                     double scene_length) {
  Eigen::Vector3d gap = x_c - x_p;
  const bool cylindrical = j.type == SceneJointType::kCylindrical;
  if (cylindrical) gap -= gap.dot(j.axis.normalized()) * j.axis.normalized();
  if (j.type != SceneJointType::kSpherical && j.type != SceneJointType::kRevolute &&
      j.type != SceneJointType::kUniversal && !cylindrical) {
    return;
  }
  const double tolerance = 1e-6 * std::max(scene_length, 1e-3 * std::max(x_p.norm(), x_c.norm()));
  if (gap.norm() <= tolerance) return;
  char buffer[400];
  std::snprintf(buffer, sizeof buffer,
                ": %s joint between nodes '%s' and '%s': the nodes are %.6g apart at t = 0 (gap (%.6g, %.6g, %.6g)%s); "
                "a %s joint needs them at one point: move the bodies or use a rigid joint for an offset",
                Name(j.type), j.node.c_str(), j.parent.c_str(), gap.norm(), gap.x(), gap.y(), gap.z(),
                cylindrical ? " across the axis" : "", Name(j.type));
  throw InputError(j.where + buffer);
}

}  // namespace

namespace {

// Point probes: the material point of the body at the probe's point (scene coordinates at the
// initial placement, i.e. part axes through the body's placement), interpolated in the cell of
// the file's mesh that holds it or, within the mesh size outside every cell, at the nearest mesh
// node; the stress at the body's stress point nearest to it. Effort probes: the prescribed
// coordinates of the node's joint.
// A point of a beam body (2-node elements, 6 coordinates per node): the section of the element
// whose axis passes nearest, at the point's projection on it (clamped to the element's ends),
// carried rigidly: u(X) = u_axis(s) + theta(s) x r, r from the axis point to X. Along the element
// (s in [0, 1], length L, axis e, P = 1 - e e^T) the axial displacement and the twist are linear
// in the end nodes' values, the transverse displacement is Hermite's cubic through the nodes'
// displacements and slopes theta x e,
//   u_perp(s) = P (H1 u_a + H3 u_b) + L (H2 theta_a + H4 theta_b) x e,
//   H1 = 1 - 3s^2 + 2s^3, H2 = s - 2s^2 + s^3, H3 = 3s^2 - 2s^3, H4 = s^3 - s^2,
// and the bending rotation is e x du_perp/dx: exact for Euler-Bernoulli elements; a Timoshenko
// element's shear deflection inside the element, which the nodes' rotations do not carry, is
// left out (at the nodes it is exact). Returns the 3 x n map from the body's coordinates, as
// `shape` of Scene::PointProbe; `cell`, `s` and `distance` (from the axis) say where.
Eigen::MatrixXd BeamPointShape(const Visualization& mesh, const Eigen::Vector3d& X, int* cell, double* s_out,
                               double* distance, double* length) {
  *cell = -1;
  *distance = std::numeric_limits<double>::infinity();
  for (int c = 0; c < mesh.cells.rows(); ++c) {
    const Eigen::Vector3d a = mesh.nodes.row(mesh.cells(c, 0)).transpose(),
                          d = mesh.nodes.row(mesh.cells(c, 1)).transpose() - a;
    const double L2 = d.squaredNorm();
    if (!(L2 > 0)) continue;
    const double s = std::clamp((X - a).dot(d) / L2, 0.0, 1.0), away = (X - a - s * d).norm();
    if (away < *distance) *cell = c, *s_out = s, *distance = away, *length = std::sqrt(L2);
  }
  const int n = int(mesh.shapes.cols());
  if (*cell < 0) return Eigen::MatrixXd::Zero(3, n);
  const int a = mesh.cells(*cell, 0), b = mesh.cells(*cell, 1);
  const Eigen::Vector3d Xa = mesh.nodes.row(a).transpose(), Xb = mesh.nodes.row(b).transpose();
  const double L = *length, s = *s_out;
  const Eigen::Vector3d e = (Xb - Xa) / L;
  const Eigen::Matrix3d E = e * e.transpose(), P = Eigen::Matrix3d::Identity() - E,
                        C = -Skew(e);  // C theta = theta x e
  const auto rows = [&](int node, int at) { return mesh.shapes.middleRows(6L * node + at, 3); };
  const Eigen::MatrixXd Ua = rows(a, 0), Ta = rows(a, 3), Ub = rows(b, 0), Tb = rows(b, 3);
  const double H1 = 1 - 3 * s * s + 2 * s * s * s, H2 = s - 2 * s * s + s * s * s, H3 = 3 * s * s - 2 * s * s * s,
               H4 = s * s * s - s * s;
  const double D1 = -6 * s + 6 * s * s, D2 = 1 - 4 * s + 3 * s * s, D3 = 6 * s - 6 * s * s,
               D4 = 3 * s * s - 2 * s;  // dH/ds
  const Eigen::MatrixXd u_axis = E * ((1 - s) * Ua + s * Ub) + P * (H1 * Ua + H3 * Ub) + L * C * (H2 * Ta + H4 * Tb);
  const Eigen::MatrixXd slope = P * (D1 * Ua + D3 * Ub) / L + C * (D2 * Ta + D4 * Tb);  // du_perp / dx
  const Eigen::MatrixXd theta = E * ((1 - s) * Ta + s * Tb) + Skew(e) * slope;
  const Eigen::Vector3d r = X - (Xa + s * L * e);
  return u_axis - Skew(r) * theta;
}

void ResolveProbes(const SceneSpec& spec, Scene& scene) {
  const SystemModel& model = scene.model;
  for (const SceneProbeSpec& p : spec.probes) {
    scene.stress_probes.emplace_back(-1, -1);
    scene.point_probes.emplace_back();
    scene.effort_coordinates.emplace_back();
    const auto has = [&](ProbeQuantity q) { return std::count(p.quantities.begin(), p.quantities.end(), q) > 0; };
    if (p.body.empty()) {
      if (!has(ProbeQuantity::kEffort)) continue;
      const int k = scene.node_index.at(p.node);
      for (size_t i = 0; i < model.prescribed.size(); ++i) {
        if (model.prescribed[i].node == k) scene.effort_coordinates.back().push_back(int(i));
      }
      if (scene.effort_coordinates.back().empty()) {
        throw InputError(
            p.where + ": probe '" + p.name + "': node '" + p.node +
            "' has no prescribed joint coordinate (effort is the force or torque that keeps a prescribed motion)");
      }
      continue;
    }
    int b = 0;
    while (b < int(spec.bodies.size()) && spec.bodies[size_t(b)].name != p.body) ++b;
    if (b == int(spec.bodies.size())) {
      throw InputError(p.where + ": probe '" + p.name + "': no body '" + p.body + "' in the scene");
    }
    const SceneBodySpec& body = spec.bodies[size_t(b)];
    const Eigen::Vector3d X = ExpSO3(body.rotation).transpose() * (p.point - body.position);
    char buffer[300];
    if (has(ProbeQuantity::kPosition) || has(ProbeQuantity::kVelocity) || has(ProbeQuantity::kAcceleration) ||
        has(ProbeQuantity::kDeformation)) {
      Scene::PointProbe& probe = scene.point_probes.back();
      probe.body = b;
      probe.s0 = X - scene.mesh_origin[size_t(b)];
      const int n = model.bodies[size_t(b)].n_coordinates();
      probe.shape = Eigen::MatrixXd::Zero(3, n);
      if (body.type != SceneBodyType::kRigid) {
        if (!scene.meshes[size_t(b)]) {
          throw InputError(p.where + ": probe '" + p.name + "': body '" + p.body + "' has no mesh in " +
                           body.superelement + " (reduce it with reduction.keep_mesh: true)");
        }
        const Visualization& mesh = *scene.meshes[size_t(b)];
        if (mesh.cell_type == "line2" && mesh.dofs_per_node == 6 && mesh.cells.cols() == 2) {
          int cell = -1;
          double s = 0, distance = 0, length = 0;
          probe.shape = BeamPointShape(mesh, X, &cell, &s, &distance, &length);
          if (cell < 0 || distance > length) {
            std::snprintf(buffer, sizeof buffer,
                          "point (%.6g, %.6g, %.6g) lies outside body '%s': %.3g from the axis of its nearest beam "
                          "element, more than the element's length (%.3g)",
                          p.point.x(), p.point.y(), p.point.z(), p.body.c_str(), distance, length);
            throw InputError(p.where + ": probe '" + p.name + "': " + buffer);
          }
          std::snprintf(buffer, sizeof buffer,
                        "probe '%s': point of body '%s' on beam element %d of its mesh, at %.4g of its length, %.3g "
                        "from its axis",
                        p.name.c_str(), p.body.c_str(), cell, s, distance);
        } else {
          const MeshPoint at = LocateInMesh(mesh.nodes, mesh.cells, mesh.cell_type, X);
          if (at.cell < 0 && at.distance > at.size) {
            std::snprintf(buffer, sizeof buffer,
                          "point (%.6g, %.6g, %.6g) lies outside body '%s': %.3g from its nearest mesh node, more than "
                          "the mesh size there (%.3g)",
                          p.point.x(), p.point.y(), p.point.z(), p.body.c_str(), at.distance, at.size);
            throw InputError(p.where + ": probe '" + p.name + "': " + buffer);
          }
          // u(X) = sum_a N_a u_a; a node with rotations (beams, shells) carries its section
          // rigidly: u + theta x (X - X_node).
          const int per = mesh.dofs_per_node;
          for (size_t a = 0; a < at.nodes.size(); ++a) {
            probe.shape += at.weights[a] * mesh.shapes.middleRows(long(per) * at.nodes[a], 3);
            if (per == 6) {
              const Eigen::Vector3d arm = X - mesh.nodes.row(at.nodes[a]).transpose();
              probe.shape -= at.weights[a] * Skew(arm) * mesh.shapes.middleRows(long(per) * at.nodes[a] + 3, 3);
            }
          }
          if (at.cell >= 0) {
            std::snprintf(buffer, sizeof buffer, "probe '%s': point of body '%s' in cell %d of its mesh",
                          p.name.c_str(), p.body.c_str(), at.cell);
          } else {
            std::snprintf(
                buffer, sizeof buffer,
                "probe '%s': body '%s' at its mesh node %d (%.6g, %.6g, %.6g) in part axes, %.3g from the given point",
                p.name.c_str(), p.body.c_str(), at.nearest, mesh.nodes(at.nearest, 0), mesh.nodes(at.nearest, 1),
                mesh.nodes(at.nearest, 2), at.distance);
          }
        }
        scene.notes.push_back(buffer);
      }
    }
    if (!has(ProbeQuantity::kStress)) continue;
    if (!scene.stresses[size_t(b)]) {
      throw InputError(p.where + ": probe '" + p.name + "': body '" + p.body + "' has no modal stresses" +
                       (body.type == SceneBodyType::kRigid
                            ? std::string(" (a rigid body)")
                            : " in " + body.superelement +
                                  " (reduce it with the mesh kept: reduction.keep_mesh, reduction.stresses)"));
    }
    const ModalStress& st = *scene.stresses[size_t(b)];
    if (st.n_points() == 0) {
      throw InputError(p.where + ": probe '" + p.name + "': body '" + p.body +
                       "' has no stress points (beams of "
                       "'general' sections have section forces only)");
    }
    Eigen::Index nearest = 0;
    (st.points.rowwise() - X.transpose()).rowwise().squaredNorm().minCoeff(&nearest);
    scene.stress_probes.back() = {b, int(nearest)};
    std::snprintf(
        buffer, sizeof buffer,
        "probe '%s': stress point %ld of body '%s' at (%.6g, %.6g, %.6g) in part axes, %.3g from the given point",
        p.name.c_str(), long(nearest), p.body.c_str(), st.points(nearest, 0), st.points(nearest, 1),
        st.points(nearest, 2), (st.points.row(nearest).transpose() - X).norm());
    scene.notes.push_back(buffer);
  }
}

// outputs.stress_exclude: per body with stresses, the mesh nodes within the distance of the
// nodes the named interfaces' couplings tie.
void ResolveStressExclusion(const SceneSpec& spec, Scene& scene) {
  const StressExcludeSpec& ex = spec.stress_exclude;
  scene.stress_excluded.assign(scene.stresses.size(), {});
  if (ex.distance < 0) return;
  if (!spec.stresses) {
    scene.notes.push_back(ex.where + ": has no effect without outputs.stresses: true");
  }
  // "<body>.<interface>" named, or every interface of every body.
  std::vector<std::vector<int>> chosen(spec.bodies.size());  // per body: its interfaces
  for (const std::string& name : ex.interfaces) {
    const size_t dot = name.find('.');
    const std::string body_name = name.substr(0, dot), interface = name.substr(dot + 1);
    size_t b = 0;
    while (b < spec.bodies.size() && spec.bodies[b].name != body_name) ++b;
    if (b == spec.bodies.size())
      throw InputError(ex.where + ": stress_exclude.interfaces: no body '" + body_name + "' in the scene");
    int k = -1;
    const auto& names = scene.interface_names[b];
    for (size_t i = 0; i < names.size(); ++i)
      if (names[i] == interface) k = int(i);
    if (k < 0) {
      std::string known;
      for (const std::string& n : names) known += (known.empty() ? "" : ", ") + n;
      throw InputError(ex.where + ": stress_exclude.interfaces: body '" + body_name + "' has no interface '" +
                       interface + "' (it has: " + known + ")");
    }
    chosen[b].push_back(k);
  }
  for (size_t b = 0; b < spec.bodies.size(); ++b) {
    if (!scene.stresses[b] || !scene.meshes[b]) continue;
    if (ex.interfaces.empty()) {
      for (size_t k = 0; k < scene.interface_names[b].size(); ++k) chosen[b].push_back(int(k));
    }
    if (chosen[b].empty()) continue;
    const Visualization& mesh = *scene.meshes[b];
    // The nodes the chosen couplings tie (files without the sets: the interface points).
    std::vector<Eigen::Vector3d> seeds;
    for (int k : chosen[b]) {
      if (size_t(k) < mesh.interface_nodes.size()) {
        for (int node : mesh.interface_nodes[size_t(k)]) seeds.push_back(mesh.nodes.row(node).transpose());
      } else {
        seeds.push_back(scene.interface_points[b][size_t(k)]);
      }
    }
    std::vector<char>& out = scene.stress_excluded[b];
    out.assign(size_t(mesh.nodes.rows()), 0);
    long count = 0;
    for (long i = 0; i < mesh.nodes.rows(); ++i) {
      const Eigen::Vector3d x = mesh.nodes.row(i).transpose();
      for (const Eigen::Vector3d& s : seeds) {
        if ((x - s).squaredNorm() <= ex.distance * ex.distance) {
          out[size_t(i)] = 1, ++count;
          break;
        }
      }
    }
    char buffer[200];
    std::snprintf(
        buffer, sizeof buffer,
        "body '%s': %ld of %ld mesh nodes within %.3g of its couplings left out of its largest von Mises stress",
        spec.bodies[b].name.c_str(), count, long(mesh.nodes.rows()), ex.distance);
    scene.notes.push_back(buffer);
  }
}

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
  if (gap <= 1e-9 * std::max(BoundingDiagonal(model.node_x0), 1e-300)) return;
  char buffer[200];
  std::snprintf(buffer, sizeof buffer, ", which opens the loop closed by %s by %.3g at the start",
                worst >= 0 && size_t(worst) < model.cut_joints.size() ? model.cut_joints[size_t(worst)].name.c_str()
                                                                      : "a cut joint",
                gap);
  throw InputError(moved + buffer +
                   " (the scene places the mechanism at 0): place the bodies at the drive's start "
                   "position, or give the function an offset so that it is 0 at t = 0");
}

}  // namespace

Scene BuildScene(const SceneSpec& spec) {
  Scene scene;
  scene.spec = spec;
  SystemModel& model = scene.model;
  const std::filesystem::path base = std::filesystem::path(spec.file).parent_path();
  std::map<std::string, std::pair<Eigen::Vector3d, std::string>> placed;  // node -> position, by body
  std::vector<std::pair<int, int>> rigid_attachments;                     // (child node, COM node)
  for (const SceneBodySpec& b : spec.bodies) scene.origin += b.position / double(spec.bodies.size());
  for (const SceneBodySpec& b_spec : spec.bodies) {
    SceneBodySpec b = b_spec;
    b.position -= scene.origin;
    if (b.type == SceneBodyType::kRigid) {
      // A rigid body: one node at the centre of mass carrying the 6 x 6 rigid mass, no
      // stiffness; its attachment points are rigid offsets (dependent nodes) of that node.
      Superelement se;
      se.name = b.name;
      se.units = UnitSystemOf(spec.units);
      se.interfaces.push_back({"com", b.center_of_mass, Eigen::Matrix3d::Identity()});
      se.K = Eigen::MatrixXd::Zero(6, 6);
      se.M = Eigen::MatrixXd::Zero(6, 6);
      se.M.topLeftCorner(3, 3) = b.mass * Eigen::Matrix3d::Identity();
      se.M.bottomRightCorner(3, 3) = b.inertia;
      se.floating_frame.type = "interface:com";
      se.floating_frame.origin = b.center_of_mass;
      se.floating_frame.Phi_CB = Eigen::MatrixXd::Identity(6, 6);
      se.mass_properties = {b.mass, b.center_of_mass, b.inertia};
      const Eigen::Matrix3d R = ExpSO3(b.rotation);
      const std::string com_node = b.nodes.at("com");
      if (scene.node_index.count(com_node)) {
        throw InputError(b.where + ": rigid body '" + b.name + "': its centre-of-mass node '" + com_node +
                         "' is already used by another body");
      }
      const int com = AddNode(model, com_node, b.position + R * b.center_of_mass, R);
      scene.node_index[com_node] = com;
      placed[com_node] = {model.node_x0[com], b.name};
      model.bodies.emplace_back(se, SuperelementOptions{}, R, b.position);
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
        rigid_attachments.emplace_back(k, com);
        scene.stick_nodes.back().push_back(k);
      }
      continue;
    }
    std::filesystem::path file(b.superelement);
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
    const Eigen::Matrix3d R = ExpSO3(b.rotation);
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
    const bool midpoint = spec.analysis.integrator == IntegratorType::kMidpoint;
    options.geometric_stiffening = b.geometric_stiffening.value_or(!midpoint);
    const bool file_has_stiffening = !se.inertia_stiffness.empty();
    if (b.geometric_stiffening.value_or(false) && !file_has_stiffening) {
      throw InputError(b.where + ": body '" + b.name + "': options.geometric_stiffening is true but " + file.string() +
                       " has no geometric stiffening (reduce it with reduction.geometric_stiffening: true)");
    }
    const bool imported = se.provenance.element_type.rfind("imported", 0) == 0;
    if (!b.geometric_stiffening.has_value() && !file_has_stiffening && se.n_reduced_dofs() > 6) {
      // What a linear body costs: in a rotating part the centrifugal stiffening of its bending
      // (rotating_beam example: one body without it 43-59% off, with it 2.2%).
      scene.notes.push_back("body '" + b.name + "': " + file.string() +
                            " has no geometric stiffening; the body is "
                            "linear inside, so a rotating or highly loaded part misses its stress stiffening (" +
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
      scene.notes.push_back("body '" + b.name + "': " + file.string() +
                            " has no inertia invariants (an older "
                            "femb-reduce wrote it): the corotational inertia (thesis 3.22) approximates the "
                            "centrifugal and Coriolis coupling of the deformation (a spinning bar stretched 21% too "
                            "much); reduce the part again for the exact inertia");
    }
    if (midpoint && file_has_stiffening && !b.geometric_stiffening.has_value()) {
      scene.notes.push_back(
          "body '" + b.name +
          "': the midpoint integrator keeps the body linear inside, whose energy it "
          "conserves exactly: the file's geometric stiffening is not used (generalized_alpha uses it; "
          "options.geometric_stiffening: true forces it)");
    }
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
  // The joint tree. Every node has at most one holder: a parent node or the ground
  // (kGround), which it hangs on through a tree joint. The rigid bodies' offsets
  // and then the scene's joints -- prescribed ones first, then in the scene's order -- go into
  // the tree while they can; a joint that would give its node a second holder or close a cycle
  // is cut: imposed by constraint equations with Lagrange multipliers, its node keeping its own
  // coordinates (solver/joints/loop_closure.h). `cut: true` cuts a joint on purpose.
  std::vector<const SceneJointSpec*> order;
  for (const SceneJointSpec& j : spec.joints)
    if (!j.prescribed.empty()) order.push_back(&j);
  for (const SceneJointSpec& j : spec.joints)
    if (j.prescribed.empty() && !j.cut) order.push_back(&j);
  for (const SceneJointSpec& j : spec.joints)
    if (j.cut) order.push_back(&j);
  constexpr int kNoHolder = -2;
  std::vector<int> holder(size_t(model.n_nodes()), kNoHolder);
  const auto is_ancestor = [&](int k, int m) {  // k on m's chain of holders (m itself included)
    for (; m >= 0; m = holder[size_t(m)])
      if (m == k) return true;
    return false;
  };
  const auto hidden_ground = [&](int k) {  // a clamped node at node k, world axes
    const int g = AddNode(model, model.node_names[k] + ".ground", model.node_x0[k], Eigen::Matrix3d::Identity());
    Clamp(model, g);
    holder.push_back(kGround);
    return g;
  };
  const auto add_cut = [&](JointType type, int k, int p, const Eigen::Vector3d& axis, const Eigen::Vector3d& axis2,
                           const std::string& name) {
    CutJoint cut;
    cut.joint =
        MakeNodeJoint(type, k, p, axis, model.node_x0[p], model.node_R0[p], model.node_x0[k], model.node_R0[k], axis2);
    cut.name = name;
    for (int i = 0; i < ConstraintCount(type); ++i) cut.equations.push_back(i);
    model.cut_joints.push_back(cut);
  };
  const auto add_tree = [&](JointType type, int k, int p, const Eigen::Vector3d& axis, const Eigen::Vector3d& axis2) {
    if (p == kGround) {
      JointToGround(model, type, k, axis, axis2);
    } else {
      model.joints.push_back(MakeNodeJoint(type, k, p, axis, model.node_x0[p], model.node_R0[p], model.node_x0[k],
                                           model.node_R0[k], axis2));
    }
    holder[size_t(k)] = p;
  };
  // Rigid bodies: the tree of one is rooted at its first point, in that order, that carries a
  // joint not cut on purpose (a pendulum's pivot), so that the joint acts on the root; else at
  // its centre of mass.
  std::map<int, int> root_of;  // COM node -> root node
  for (const SceneJointSpec* j : order) {
    if (j->cut) continue;
    const int k = scene.node_index.at(j->node);
    for (const auto& [point, com] : rigid_attachments)
      if ((point == k || com == k) && !root_of.count(com)) root_of[com] = k;
  }
  for (const auto& [k, com] : rigid_attachments) {
    const bool rooted_here = root_of.count(com) && root_of[com] == k;
    const int child = rooted_here ? com : k, parent = rooted_here ? k : com;
    if (holder[size_t(child)] != kNoHolder || is_ancestor(child, parent)) {
      add_cut(JointType::kRigid, child, parent, Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY(),
              "rigid offset of node '" + model.node_names[k] + "' on the body at node '" + model.node_names[com] + "'");
      continue;
    }
    add_tree(JointType::kRigid, child, parent, Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY());
  }
  // The bounding box diagonal of the nodes: the scale of position tolerances.
  const double scene_length = BoundingDiagonal(model.node_x0);
  for (const SceneJointSpec* jp : order) {
    const SceneJointSpec& j = *jp;
    const int k = scene.node_index.at(j.node);
    const int p = j.parent.empty() ? kGround : scene.node_index.at(j.parent);
    if (p >= 0) RequireJointGap(j, model.node_x0[p], model.node_x0[k], scene_length);
    const bool tree = !j.cut && holder[size_t(k)] == kNoHolder && !is_ancestor(k, p);
    const JointType type = SolverJointType(j.type);
    if (!tree) {
      if (!j.prescribed.empty()) {
        throw InputError(
            j.where + ": " + Name(j.type) + " joint of node '" + j.node + "' is prescribed but closes a loop (node '" +
            j.node + "' already hangs on " +
            (holder[size_t(k)] >= 0 ? "node '" + model.node_names[holder[size_t(k)]] + "'"
                                    : std::string("the ground")) +
            "); a drive must be a tree joint: swap 'node' and 'parent', or prescribe another joint of the loop");
      }
      const std::string name = j.where + ": " + Name(j.type) + " joint of node '" + j.node + "'" +
                               (p >= 0 ? " on node '" + j.parent + "'" : std::string(" to the ground"));
      add_cut(type, k, p >= 0 ? p : hidden_ground(k), j.axis, j.axis2, name);
      continue;
    }
    add_tree(type, k, p, j.axis, j.axis2);  // to a node or to the ground alike
    if (!j.prescribed.empty()) model.prescribed.push_back(PrescribedBy(spec.functions.at(j.prescribed), k));
  }
  // An over-constrained loop (a planar four-bar of spatial revolute joints) has equations that
  // repeat others: they are dropped, and the log says which.
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
  // The joint graph (cycles, two parents) before anything walks it.
  std::unique_ptr<DofMap> dofs_ptr;
  try {
    dofs_ptr = std::make_unique<DofMap>(model);
  } catch (const InputError& e) {
    throw InputError(spec.file + ": joints: " + e.what());
  }
  const DofMap& dofs = *dofs_ptr;
  RequireLoopsClosedAtStart(spec, model, dofs);
  for (const SceneLoadSpec& l : spec.loads) {
    if (l.type == SceneLoadType::kGravity) {
      model.gravity += l.g;
      if (spec.analysis.type != AnalysisType::kDynamic) model.static_gravity_end = spec.analysis.end_time;
      continue;
    }
    if (l.type == SceneLoadType::kSpring) {
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
  ResolveProbes(spec, scene);
  ResolveStressExclusion(spec, scene);
  return scene;
}

}  // namespace femb
