#include "solver/scene/scene_outputs.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "formats/input_error.h"
#include "formats/solid_shape.h"
#include "solver/rotation.h"

namespace femb {

namespace {

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

}  // namespace

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
      if (body.type != BodyType::kRigid) {
        if (!scene.meshes[size_t(b)]) {
          throw InputError(p.where + ": probe '" + p.name + "': body '" + p.body + "' has no mesh in " +
                           body.superelement + " (reduce it with reduction.keep_mesh: true)");
        }
        const Visualization& mesh = *scene.meshes[size_t(b)];
        if (mesh.cell_type == CellType::kLine2 && mesh.dofs_per_node == 6 && mesh.cells.cols() == 2) {
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
                       (body.type == BodyType::kRigid
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

}  // namespace femb
