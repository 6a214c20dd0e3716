// The part file (YAML): what femb-reduce reads. Parsing checks every value it can check without
// numerics (ranges, names, geometry of points) and names FILE:LINE: key on failure.
// The format is documented in formats/PART_FORMAT.md.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "formats/kinds.h"
#include "formats/superelement.h"

namespace femb {

/// Isotropic linear elastic material. E, rho > 0; -1 < nu < 0.5.
struct MaterialSpec {
  double E = 0.0;    ///< Young's modulus [stress]
  double nu = 0.0;   ///< Poisson's ratio [-]
  double rho = 0.0;  ///< density [mass / length^3]
};

/// A beam cross-section: a named shape with its dimensions, or explicit properties.
struct BeamSectionSpec {
  SectionShape shape = SectionShape::kGeneral;
  // circle: diameter; tube: outer_radius + wall; rectangle: width (local y) + height (local z).
  double diameter = 0.0, outer_radius = 0.0, wall = 0.0, width = 0.0, height = 0.0;
  // general: A, Iy = int z^2 dA, Iz = int y^2 dA, J (torsion constant); shear factors ky, kz
  // (shear area = k A; 0 = rigid in shear); Ip polar moment for rotary inertia (default Iy + Iz).
  double A = 0.0, Iy = 0.0, Iz = 0.0, J = 0.0, ky = 0.0, kz = 0.0, Ip = 0.0;
  std::string where;  ///< location for error messages
};

struct BeamSegmentSpec {
  int from = 0, to = 0;  ///< indices into BeamSpec::points
  int elements = 1;
  std::optional<BeamSectionSpec> section;  ///< overrides the part's section
  std::string where;
};

struct BeamSpec {
  std::vector<std::string> point_names;
  std::vector<Eigen::Vector3d> points;
  std::vector<BeamSegmentSpec> segments;
  std::optional<Eigen::Vector3d> orientation;  ///< a vector in the local x-y plane
  bool shear_deformation = true;               ///< false: Euler-Bernoulli
  BeamSectionSpec section;
};

/// Nodes picked by geometry: the mesh nodes on a surface (cylinder, sphere, plane)
/// within `tolerance`, or inside a box. reducer/mesh/node_selection.h applies it.
struct NodeSelectionSpec {
  SelectionShape shape = SelectionShape::kBox;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  ///< cylinder: on the axis; sphere: centre; plane: on it; box: min
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();  ///< cylinder: axis; plane: normal (unit); box: max
  double radius = 0.0;                              ///< cylinder, sphere
  double length = 0.0;                              ///< cylinder: 0 = unbounded, else from point along axis
  std::optional<double> tolerance;                  ///< default: 1e-4 x the mesh's bounding-box diagonal
  std::string where;
};

struct InterfaceSpec {
  std::string name;
  int point = -1;  ///< index into BeamSpec::points (beam parts)
  // solid parts: the node set (gmsh physical surface group; box: xmin ... zmax), the coupling
  // and the interface point (default: the centroid of the node set)
  std::string group;
  std::optional<NodeSelectionSpec> select;  ///< instead of `group`
  Coupling coupling = Coupling::kRbe2;
  std::optional<Eigen::Vector3d> location;
  std::string where;
};

/// A solid part: a built-in shape or a geometry/mesh file, meshed by gmsh.
struct SolidSpec {
  SolidShape shape = SolidShape::kFile;                   ///< a built-in shape, or kFile: `file`
  Eigen::Vector3d size = Eigen::Vector3d::Ones();         ///< box/plate edge lengths [length], corner at the origin
  double radius = 0.0, inner_radius = 0.0, length = 0.0;  ///< cylinder/tube along z from the origin
  std::string file;                                       ///< geometry or mesh file (resolved path)
  double element_size = 0.0;                              ///< target element size [length]
  int order = 2;                                          ///< 1: TET4/HEX8, 2: TET10/HEX20
  bool hexahedra = false;                                 ///< mesh.elements: hexahedra (box only)
  long max_elements = 3000000;                            ///< mesh.max_elements: refuse larger estimated meshes
  std::string where;
};

/// Modal derivatives (thesis 8.3): theta_ij = -K_ii^-1 (dK/dq_j) phi_i of pairs of reduced
/// coordinates' shapes, zero at the interfaces, deflated against the basis and M-orthonormalized.
struct ModalDerivativeSpec {
  bool enabled = false;
  DerivativePairs of = DerivativePairs::kAll;  ///< every pair (i <= j) of those coordinates
  std::vector<std::pair<int, int>> pairs;      ///< explicit reduced coordinate indices (then 'of' unused)
  double tolerance = 1e-4;                     ///< drop a vector whose M-norm falls below this fraction when deflated
  std::string where;
};

struct ReductionSpec {
  int internal_modes = 10;
  /// craig_bampton: fixed-interface modes; free_interface: the part's lowest free-free modes
  /// with the static constraint modes, brought to interface form by the pseudo-inverse route of
  /// thesis 8.2 (reducer/reduction/general_basis.h); internal_modes counts the free-free modes;
  /// general: shapes from a file (basis_file), the same route.
  ReductionMethod method = ReductionMethod::kCraigBampton;
  std::string where_method;
  /// method general (imported parts): the deformation shapes, a Matrix Market file (array or
  /// coordinate, real) with one row per imported DOF in the matrices' order and one column per shape.
  std::string basis_file;
  std::string where_basis;
  ModalDerivativeSpec modal_derivatives;
  FloatingFrameType floating_frame = FloatingFrameType::kCenterOfMass;
  std::string floating_frame_interface;  ///< kInterface: the interface the frame follows
  /// The key's value as the part file spells it (center_of_mass, ..., interface:<name>).
  std::string FloatingFrameWord() const {
    return floating_frame == FloatingFrameType::kInterface ? "interface:" + floating_frame_interface
                                                           : Name(floating_frame);
  }
  /// Geometric stiffening: the geometric stiffness of the basis vectors' stresses and
  /// of the 12 unit inertia load cases, and the inertia invariants of the exact kinetic energy,
  /// stored for femb-solve. Unset: on wherever it can be built (GeometricStiffening below).
  std::optional<bool> geometric_stiffening;
  /// What the reduction does: the key's value, or on for femb's own parts reduced by
  /// Craig-Bampton (the only ones with the element stresses and the basis it is built on).
  bool GeometricStiffening(PartType part_type) const {
    return geometric_stiffening.value_or(method == ReductionMethod::kCraigBampton && part_type != PartType::kImported);
  }
  /// Imported parts with a material: the stiffening is built on femb's own elements over the
  /// imported mesh's solid cells; its default there is on.
  bool GeometricStiffening(PartType part_type, bool has_material) const {
    if (part_type == PartType::kImported)
      return geometric_stiffening.value_or(has_material && method == ReductionMethod::kCraigBampton);
    return GeometricStiffening(part_type);
  }
  /// Store the mesh and mode shapes (visualization group); unset: only for models up to
  /// kKeepMeshMaxDofs DOFs (the shapes take n_dofs x n_reduced doubles).
  std::optional<bool> keep_mesh;
  static constexpr long kKeepMeshMaxDofs = 200000;
  /// Modal stresses (reducer/reduction/modal_stress.h) beside the kept mesh; unset: on
  /// whenever the mesh is kept. true without the mesh is an error.
  std::optional<bool> stresses;
  std::string where_stresses;
  /// K lowest nonzero free-free frequencies of the full model, compared with the reduced
  /// model's in the summary. Unset: up to 12 (at most the reduced model's flexible count) for
  /// models up to kFullModesMaxDofs DOFs, none above; 0: none.
  int full_modes = 0;
  bool full_modes_given = false;
  static constexpr long kFullModesMaxDofs = 200000;
  double memory_limit_gb = 0;  ///< refuse when the Cholesky factor would exceed it (0: MemAvailable); with
                               ///< the petsc solver, the limit of each rank's share
  /// Unset: cholmod on one process, petsc when femb-reduce runs on more than one (mpirun -np N).
  std::optional<ReductionSolver> solver;
  std::string where_solver;
  std::string where_floating_frame;
};

/// Imported matrices (`type: imported`): K and M of a model assembled by another FE
/// code, with the node coordinates from `geometry.file` (SolidSpec::file).
struct MatricesSpec {
  MatrixFormat format = MatrixFormat::kCalculix;
  std::string stiffness, mass;  ///< resolved paths
  std::string dofs;             ///< calculix: job.dof; matrix_market: the row -> (node, component) CSV
  /// abaqus: the deck the matrices came from (the geometry file), which numbers the equations of
  /// the coordinate form (formats/abaqus_deck.h); "" when the geometry is not an Abaqus deck.
  std::string deck;
  std::string instance;  ///< abaqus: the deck's instance the part is (needed when it has several)
  std::string where;
};

struct PartSpec {
  std::string file;
  std::string text_hash;  ///< FNV-1a 64-bit of the file text (after --set), hex
  std::string name;
  PartType type = PartType::kBeam;
  Units units;
  MaterialSpec material;
  /// Imported parts: `material:` given (optional there), for femb's own elements on the imported
  /// mesh's solid cells: the geometric stiffening. Always true for beams and solids.
  bool has_material = true;
  BeamSpec beam;
  SolidSpec solid;        ///< solid; imported: file and where only
  MatricesSpec matrices;  ///< imported
  std::vector<InterfaceSpec> interfaces;
  ReductionSpec reduction;
  bool check_units = true;  ///< flag implausible (mixed-unit) density, modulus and part size
};

/// Mixed-unit check of a part's overall size (bounding-box diagonal) against its unit system:
/// throws InputError "`where`: ... looks like <other system>" when implausible (a part of
/// 1 .. 50000 mm). No-op when part.check_units is false.
void CheckPartSize(const PartSpec& part, double diagonal, const std::string& where);

/// Reads and checks a part file; `overrides` are "key.path=value" strings applied first.
/// Throws InputError naming FILE:LINE and the key for any problem.
PartSpec ReadPartFile(const std::string& path, const std::vector<std::string>& overrides = {});

/// Same, from text (`name` is used in messages).
PartSpec ParsePart(const std::string& text, const std::string& name, const std::vector<std::string>& overrides = {});

/// The named consistent unit systems: "SI", "mm-t-s", "mm-kg-ms". Throws InputError otherwise.
Units UnitSystem(const std::string& name, const std::string& where);

}  // namespace femb
