// From a scene file to a system model: loads the superelement files, maps interface nodes to
// scene nodes (shared names are rigid connections), applies joints to ground and loads, and
// checks consistency (one clear error per problem, naming FILE:LINE).
#pragma once

#include <map>
#include <optional>
#include <string>

#include "formats/scene_file.h"
#include "solver/assembly/system.h"

namespace femb {

struct Scene {
  SceneSpec spec;
  SystemModel model;
  std::map<std::string, int> node_index;
  std::vector<std::string> body_names;
  /// The model is computed in coordinates relative to this point (the mean of the bodies'
  /// placements): a scene placed 1e4 m from the origin is then solved as accurately as one at
  /// the origin. Node positions in the model and its states are relative to it; the results
  /// writer adds it back.
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::VectorXd initial_velocity;  ///< over the unknowns
  /// Per body: the mesh and mode shapes of its superelement file (animation), if any, and the
  /// floating frame origin they refer to (part axes).
  std::vector<std::optional<Visualization>> meshes;
  std::vector<Eigen::Vector3d> mesh_origin;
  /// Per body: its file's modal stresses, loaded when the scene asks for stresses
  /// (outputs.stresses or a stress probe on the body).
  std::vector<std::optional<ModalStress>> stresses;
  /// Per probe: for a stress probe the body and its stress point nearest to the probe's point
  /// (-1, -1 for node probes).
  std::vector<std::pair<int, int>> stress_probes;
  /// Per probe: for a point probe's position, velocity, acceleration and deformation the body
  /// (-1: none), the point from the body's floating frame origin in part axes (undeformed) and
  /// its displacement field, u(X) = shape q_loc (3 x the body's coordinates; zero for a rigid body).
  struct PointProbe {
    int body = -1;
    Eigen::Vector3d s0 = Eigen::Vector3d::Zero();
    Eigen::MatrixXd shape;
  };
  std::vector<PointProbe> point_probes;
  /// Per probe: for an effort probe the prescribed coordinates of its node (SystemModel::prescribed).
  std::vector<std::vector<int>> effort_coordinates;
  /// Per body: its interfaces' names and points (part axes), as in its file.
  std::vector<std::vector<std::string>> interface_names;
  std::vector<std::vector<Eigen::Vector3d>> interface_points;
  /// Per body with stresses and outputs.stress_exclude: per mesh node 1 when it is left out of
  /// the body's largest von Mises stress (empty: none).
  std::vector<std::vector<char>> stress_excluded;
  /// Per body without a mesh (rigid bodies, superelements reduced without keeping theirs): the
  /// scene nodes the animation joins by lines from the first one (a rigid body: its centre of
  /// mass to each of its points; a superelement: its first interface to the others).
  std::vector<std::vector<int>> stick_nodes;
  /// Lines for the log (e.g. a body whose file has no geometric stiffening).
  std::vector<std::string> notes;
};

/// Throws InputError for: a missing or wrong-version superelement file, an interface name the
/// file does not have, an interface left unmapped, a node placed at different points by two
/// bodies, a load or probe on an unknown node, a load on a clamped node.
Scene BuildScene(const SceneSpec& spec);

}  // namespace femb
