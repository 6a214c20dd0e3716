#include "formats/superelement_file.h"

#include <unistd.h>

#include <cstdio>
#include <filesystem>

#include "formats/hdf5_file.h"
#include "formats/input_error.h"

namespace femb {
namespace {

// The root's format attributes, the units and the interfaces.
void WriteHeader(const Superelement& se, h5::Writer& w) {
  w.Attribute("/", "format", kSuperelementFormatTag);
  w.Attribute("/", "format_version",
              std::to_string(kSuperelementFormatMajor) + "." + std::to_string(kSuperelementFormatMinor));
  w.Attribute("/", "format_version_major", kSuperelementFormatMajor);
  w.Attribute("/", "format_version_minor", kSuperelementFormatMinor);
  w.Attribute("/", "name", se.name);

  w.CreateGroup("/units");
  w.Attribute("/units", "system", se.units.system);
  w.Attribute("/units", "length", se.units.length);
  w.Attribute("/units", "mass", se.units.mass);
  w.Attribute("/units", "time", se.units.time);
  w.Attribute("/units", "force", se.units.force);
  w.Attribute("/units", "stress", se.units.stress);
  w.Attribute("/units", "angle", se.units.angle);

  const int N = se.n_interface_nodes();
  w.CreateGroup("/interfaces");
  std::vector<std::string> names;
  Eigen::MatrixXd positions(N, 3), orientations(N, 9);
  for (int k = 0; k < N; ++k) {
    names.push_back(se.interfaces[k].name);
    positions.row(k) = se.interfaces[k].position.transpose();
    Eigen::Matrix<double, 3, 3, Eigen::RowMajor> R = se.interfaces[k].orientation;
    orientations.row(k) = Eigen::Map<const Eigen::Matrix<double, 1, 9>>(R.data());
  }
  w.Strings("/interfaces/names", names);
  w.Matrix("/interfaces/positions", positions);
  w.Matrix("/interfaces/orientations", orientations);
}

// The reduced matrices, their coordinates' labels and counts, the internal frequencies.
void WriteReduced(const Superelement& se, h5::Writer& w) {
  w.CreateGroup("/reduced");
  w.Matrix("/reduced/K", se.K);
  w.Matrix("/reduced/M", se.M);
  std::vector<std::string> labels;
  for (int i = 0; i < se.n_reduced_dofs(); ++i) labels.push_back(ReducedCoordinateLabel(se, i));
  w.Strings("/reduced/labels", labels);
  w.Attribute("/reduced", "n_interface_dofs", long(se.n_interface_dofs()));
  w.Attribute("/reduced", "n_internal_modes", long(se.n_internal_modes()));
  w.Attribute("/reduced", "n_modal_derivatives", se.n_modal_derivatives);
  w.Vector("/reduced/internal_frequencies_hz", se.internal_frequencies_hz);
  if (se.n_modal_derivatives > 0) {
    Eigen::MatrixXi pairs(long(se.modal_derivative_pairs.size()), 2);
    for (size_t k = 0; k < se.modal_derivative_pairs.size(); ++k)
      pairs.row(long(k)) << se.modal_derivative_pairs[k].first, se.modal_derivative_pairs[k].second;
    w.IntMatrix("/reduced/modal_derivative_pairs", pairs);
  }
}

// Thesis 8.2 case 4: the interface constraint C q_int = 0 of a basis that moves fewer interface
// directions than the interfaces have.
void WriteInterfaceConstraint(const Superelement& se, h5::Writer& w) {
  if (se.interface_constraint.rows() == 0) return;
  if (se.interface_constraint.cols() != se.n_interface_dofs()) {
    throw InputError("the interface constraint has " + std::to_string(se.interface_constraint.cols()) +
                     " columns, the file " + std::to_string(se.n_interface_dofs()) + " interface coordinates");
  }
  w.Matrix("/reduced/interface_constraint", se.interface_constraint);
}

// The reduced internal force's polynomial and the inertia load cases' geometric stiffness.
void WriteNonlinear(const Superelement& se, h5::Writer& w) {
  if (se.polynomial) {
    w.CreateGroup("/reduced/polynomial");
    w.Matrix("/reduced/polynomial/A", se.polynomial->A);
    if (se.polynomial->cubic()) w.Matrix("/reduced/polynomial/B", se.polynomial->B);
  }
  if (!se.inertia_stiffness.empty()) {
    // The 12 reduced geometric stiffness matrices of the unit inertia load cases, stacked
    // (12 n x n; case k in rows k n .. k n + n - 1), in the order of kInertiaLoadCases.
    const long n = se.n_reduced_dofs();
    if (se.inertia_stiffness.size() != size_t(kInertiaLoadCaseCount)) {
      throw InputError(std::to_string(se.inertia_stiffness.size()) + " inertia stiffness matrices (need " +
                       std::to_string(kInertiaLoadCaseCount) + ")");
    }
    for (const Eigen::MatrixXd& K_sigma : se.inertia_stiffness) {
      if (K_sigma.rows() != n || K_sigma.cols() != n) {
        throw InputError("an inertia stiffness matrix is " + std::to_string(K_sigma.rows()) + " x " +
                         std::to_string(K_sigma.cols()) + ", the reduced K " + std::to_string(n) + " x " +
                         std::to_string(n));
      }
    }
    Eigen::MatrixXd stacked(kInertiaLoadCaseCount * n, n);
    for (int k = 0; k < kInertiaLoadCaseCount; ++k) stacked.middleRows(k * n, n) = se.inertia_stiffness[size_t(k)];
    w.CreateGroup("/reduced/geometric_stiffness");
    w.Matrix("/reduced/geometric_stiffness/inertia", stacked);
    std::string cases;
    for (int k = 0; k < kInertiaLoadCaseCount; ++k) cases += std::string(k ? " " : "") + kInertiaLoadCases[k];
    w.Attribute("/reduced/geometric_stiffness/inertia", "load_cases", cases);
  }
}

// The inertia invariants (superelement.h), stacked: Gamma 3n x n (x, y, z), Xi 6n x n.
void WriteInertiaInvariants(const Superelement& se, h5::Writer& w) {
  if (se.inertia_gamma.empty()) return;
  const long n = se.n_reduced_dofs();
  if (se.inertia_gamma.size() != 3 || se.inertia_xi.size() != 6) {
    throw InputError("inertia invariants: " + std::to_string(se.inertia_gamma.size()) + " Gamma and " +
                     std::to_string(se.inertia_xi.size()) + " Xi matrices (need 3 and 6)");
  }
  auto stack = [n](const std::vector<Eigen::MatrixXd>& blocks) {
    Eigen::MatrixXd stacked(long(blocks.size()) * n, n);
    for (size_t k = 0; k < blocks.size(); ++k) {
      if (blocks[k].rows() != n || blocks[k].cols() != n) {
        throw InputError("an inertia invariant is " + std::to_string(blocks[k].rows()) + " x " +
                         std::to_string(blocks[k].cols()) + ", the reduced K " + std::to_string(n) + " x " +
                         std::to_string(n));
      }
      stacked.middleRows(long(k) * n, n) = blocks[k];
    }
    return stacked;
  };
  w.CreateGroup("/reduced/inertia_invariants");
  w.Matrix("/reduced/inertia_invariants/Gamma", stack(se.inertia_gamma));
  w.Attribute("/reduced/inertia_invariants/Gamma", "blocks", std::string("x y z"));
  w.Matrix("/reduced/inertia_invariants/Xi", stack(se.inertia_xi));
  w.Attribute("/reduced/inertia_invariants/Xi", "blocks", std::string("xx yy zz xy xz yz"));
}

// The floating frame, the mass properties and what the file says of the full model.
void WriteFrameAndMass(const Superelement& se, h5::Writer& w) {
  w.CreateGroup("/floating_frame");
  w.Attribute("/floating_frame", "type", se.floating_frame.type);
  w.Vector("/floating_frame/origin", se.floating_frame.origin);
  w.Matrix("/floating_frame/orientation", se.floating_frame.orientation);
  w.Matrix("/floating_frame/Phi_CB", se.floating_frame.Phi_CB);
  if (se.floating_frame.cardona_weights.size() > 0) {
    w.Vector("/floating_frame/cardona_weights", se.floating_frame.cardona_weights);
  }

  w.CreateGroup("/mass_properties");
  w.Scalar("/mass_properties/mass", se.mass_properties.mass);
  w.Vector("/mass_properties/center_of_mass", se.mass_properties.center_of_mass);
  w.Matrix("/mass_properties/inertia_com", se.mass_properties.inertia_com);

  w.CreateGroup("/full_model");
  w.Attribute("/full_model", "n_dofs", se.n_full_dofs);
  if (!se.full_rigid_couplings.empty()) w.Strings("/full_model/rigid_couplings", se.full_rigid_couplings);
  if (se.full_free_free_frequencies_hz.size() > 0) {
    w.Vector("/full_model/free_free_frequencies_hz", se.full_free_free_frequencies_hz);
  }
}

// The mesh and the mode shapes on it.
void WriteVisualization(const Visualization& v, h5::Writer& w) {
  w.CreateGroup("/visualization");
  w.Attribute("/visualization", "cell_type", std::string(Name(v.cell_type)));
  w.Attribute("/visualization", "dofs_per_node", long(v.dofs_per_node));
  w.Matrix("/visualization/nodes", v.nodes);
  w.IntMatrix("/visualization/cells", v.cells);
  w.Matrix("/visualization/shapes", v.shapes);
  if (!v.interface_nodes.empty()) {
    // Ragged: the sets one after the other, and where each starts (N + 1 offsets).
    std::vector<int> flat, offsets{0};
    for (const std::vector<int>& set : v.interface_nodes) {
      flat.insert(flat.end(), set.begin(), set.end());
      offsets.push_back(int(flat.size()));
    }
    w.IntVector("/visualization/interface_nodes", flat);
    w.IntVector("/visualization/interface_node_offsets", offsets);
  }
}

// The modal stresses.
void WriteStress(const ModalStress& st, h5::Writer& w) {
  w.CreateGroup("/stress");
  w.Attribute("/stress", "method", st.method);
  w.Attribute("/stress", "components", std::string("xx yy zz yz xz xy"));
  w.Matrix("/stress/points", st.points);
  w.IntVector("/stress/node", std::vector<int>(st.node.data(), st.node.data() + st.node.size()));
  w.FloatMatrix("/stress/modes", st.modes);
  if (st.section_forces.size() > 0) {
    w.FloatMatrix("/stress/section_forces", st.section_forces);
    w.Matrix("/stress/element_axes", st.element_axes);
  }
  if (st.gradients.size() > 0) w.FloatMatrix("/stress/gradients", st.gradients);
  if (st.element_quadratic.size() > 0) {
    w.FloatMatrix("/stress/element_quadratic", st.element_quadratic);
    w.IntVector("/stress/point_element",
                std::vector<int>(st.point_element.data(), st.point_element.data() + st.point_element.size()));
  }
  if (st.gradients.size() > 0 || st.element_quadratic.size() > 0)
    w.Vector("/stress/material", Eigen::Vector2d(st.E, st.nu));
  if (st.inertia_modes.size() > 0) {
    w.FloatMatrix("/stress/inertia_modes", st.inertia_modes);
    if (st.inertia_section_forces.size() > 0)
      w.FloatMatrix("/stress/inertia_section_forces", st.inertia_section_forces);
  }
}

// Where the file came from and the reduction's stages' times.
void WriteProvenance(const Provenance& p, h5::Writer& w) {
  w.CreateGroup("/provenance");
  w.Attribute("/provenance", "femb_version", p.femb_version);
  w.Attribute("/provenance", "input_file", p.input_file);
  w.Attribute("/provenance", "input_hash", p.input_hash);
  w.Attribute("/provenance", "element_type", p.element_type);
  if (!p.reduction_method.empty()) w.Attribute("/provenance", "reduction_method", p.reduction_method);
  w.Attribute("/provenance", "n_nodes", p.n_nodes);
  w.Attribute("/provenance", "n_elements", p.n_elements);
  std::vector<std::string> stages;
  Eigen::VectorXd seconds(p.stage_seconds.size());
  for (size_t i = 0; i < p.stage_seconds.size(); ++i) {
    stages.push_back(p.stage_seconds[i].first);
    seconds[i] = p.stage_seconds[i].second;
  }
  w.Strings("/provenance/stages", stages);
  w.Vector("/provenance/stage_seconds", seconds);
}

void WriteContent(const Superelement& se, h5::Writer& w) {
  WriteHeader(se, w);
  WriteReduced(se, w);
  WriteNonlinear(se, w);
  WriteInterfaceConstraint(se, w);
  WriteInertiaInvariants(se, w);
  WriteFrameAndMass(se, w);
  if (se.visualization) WriteVisualization(*se.visualization, w);
  if (se.stress) WriteStress(*se.stress, w);
  WriteProvenance(se.provenance, w);
}

void RequireShape(const h5::Reader& r, const std::string& name, long rows, long cols) {
  Eigen::MatrixXd dummy;
  auto shape = r.Shape(name);
  bool ok = (cols < 0) ? (shape.size() == 1 && long(shape[0]) == rows)
                       : (shape.size() == 2 && long(shape[0]) == rows && long(shape[1]) == cols);
  if (!ok) {
    std::string got;
    for (auto d : shape) got += (got.empty() ? "" : " x ") + std::to_string(d);
    std::string want = std::to_string(rows) + (cols < 0 ? "" : " x " + std::to_string(cols));
    throw InputError(r.path() + ": dataset " + name + " has shape (" + got + "), expected (" + want + ")");
  }
}

}  // namespace

void WriteSuperelementFile(const Superelement& se, const std::string& path) {
  const std::string temporary = path + ".tmp." + std::to_string(::getpid());
  try {
    h5::Writer writer(temporary);
    WriteContent(se, writer);
    writer.Close();
  } catch (...) {
    std::remove(temporary.c_str());
    throw;
  }
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec) {
    std::remove(temporary.c_str());
    throw InputError(path + ": cannot rename the temporary file into place (" + ec.message() + ")");
  }
}

namespace {

// Version first: nothing else is meaningful in a file of another major version.
void RequireFormat(const h5::Reader& r) {
  const std::string& path = r.path();
  std::string tag;
  try {
    tag = r.StringAttribute("/", "format");
  } catch (const InputError&) {
    throw InputError(path + ": not a femb superelement file (no root attribute 'format')");
  }
  if (tag != kSuperelementFormatTag) {
    throw InputError(path + ": not a femb superelement file (format is '" + tag + "')");
  }
  long major = r.IntAttribute("/", "format_version_major");
  if (major != kSuperelementFormatMajor) {
    throw InputError(path + ": superelement format version " + r.StringAttribute("/", "format_version") +
                     " is not supported by this femb (reads major version " + std::to_string(kSuperelementFormatMajor) +
                     "); re-run femb-reduce on the part");
  }
}

// The name, the units and the interfaces.
void ReadHeader(const h5::Reader& r, Superelement& se) {
  se.name = r.StringAttribute("/", "name");
  se.units.system = r.StringAttribute("/units", "system");
  se.units.length = r.StringAttribute("/units", "length");
  se.units.mass = r.StringAttribute("/units", "mass");
  se.units.time = r.StringAttribute("/units", "time");
  se.units.force = r.StringAttribute("/units", "force");
  se.units.stress = r.StringAttribute("/units", "stress");
  se.units.angle = r.StringAttribute("/units", "angle");

  std::vector<std::string> names = r.Strings("/interfaces/names");
  const long N = long(names.size());
  RequireShape(r, "/interfaces/positions", N, 3);
  RequireShape(r, "/interfaces/orientations", N, 9);
  Eigen::MatrixXd positions = r.Matrix("/interfaces/positions");
  Eigen::MatrixXd orientations = r.Matrix("/interfaces/orientations");
  for (long k = 0; k < N; ++k) {
    InterfaceNode node;
    node.name = names[k];
    node.position = positions.row(k).transpose();
    Eigen::Matrix<double, 1, 9> row = orientations.row(k);
    node.orientation = Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(row.data());
    se.interfaces.push_back(node);
  }
}

// The reduced matrices and what comes with them (derivative pairs, the internal force's
// polynomial, the inertia load cases' geometric stiffness, the interface constraint, the inertia
// invariants), each checked against the reduced size n. Returns n.
long ReadReduced(const h5::Reader& r, Superelement& se) {
  const std::string& path = r.path();
  const long N = long(se.interfaces.size());
  se.internal_frequencies_hz = r.Vector("/reduced/internal_frequencies_hz");
  se.n_modal_derivatives = r.IntAttribute("/reduced", "n_modal_derivatives");
  const long n = 6 * N + se.internal_frequencies_hz.size() + se.n_modal_derivatives;
  RequireShape(r, "/reduced/K", n, n);
  RequireShape(r, "/reduced/M", n, n);
  se.K = r.Matrix("/reduced/K");
  se.M = r.Matrix("/reduced/M");
  if (se.n_modal_derivatives > 0) {
    RequireShape(r, "/reduced/modal_derivative_pairs", se.n_modal_derivatives, 2);
    const Eigen::MatrixXi pairs = r.IntMatrix("/reduced/modal_derivative_pairs");
    for (long k = 0; k < pairs.rows(); ++k) se.modal_derivative_pairs.emplace_back(pairs(k, 0), pairs(k, 1));
  }
  if (r.Exists("/reduced/polynomial")) {
    const long P = n * (n + 1) / 2;
    RequireShape(r, "/reduced/polynomial/A", n, P);
    se.polynomial = PolynomialStiffness{r.Matrix("/reduced/polynomial/A"), Eigen::MatrixXd(), Eigen::MatrixXd()};
    // B is absent when the file holds the quadratic part only (geometric stiffening).
    if (r.Exists("/reduced/polynomial/B")) {
      RequireShape(r, "/reduced/polynomial/B", P, P);
      se.polynomial->B = r.Matrix("/reduced/polynomial/B");
    }
  }
  if (r.Exists("/reduced/geometric_stiffness/inertia")) {
    RequireShape(r, "/reduced/geometric_stiffness/inertia", kInertiaLoadCaseCount * n, n);
    const Eigen::MatrixXd stacked = r.Matrix("/reduced/geometric_stiffness/inertia");
    for (int k = 0; k < kInertiaLoadCaseCount; ++k) se.inertia_stiffness.push_back(stacked.middleRows(k * n, n));
  }
  if (r.Exists("/reduced/interface_constraint")) {
    const std::vector<hsize_t> shape = r.Shape("/reduced/interface_constraint");
    const long rows = shape.size() == 2 ? long(shape[0]) : 0;
    if (shape.size() != 2) RequireShape(r, "/reduced/interface_constraint", 1, 6 * N);  // names the shape
    if (rows < 1 || rows > 6 * N - 6) {
      throw InputError(path + ": dataset /reduced/interface_constraint has " + std::to_string(rows) +
                       " rows (need 1 to " + std::to_string(6 * N - 6) + ": the rigid motions stay free)");
    }
    RequireShape(r, "/reduced/interface_constraint", rows, 6 * N);
    se.interface_constraint = r.Matrix("/reduced/interface_constraint");
  }
  if (r.Exists("/reduced/inertia_invariants")) {
    RequireShape(r, "/reduced/inertia_invariants/Gamma", 3 * n, n);
    RequireShape(r, "/reduced/inertia_invariants/Xi", 6 * n, n);
    const Eigen::MatrixXd gamma = r.Matrix("/reduced/inertia_invariants/Gamma");
    const Eigen::MatrixXd xi = r.Matrix("/reduced/inertia_invariants/Xi");
    for (int k = 0; k < 3; ++k) se.inertia_gamma.push_back(gamma.middleRows(k * n, n));
    for (int k = 0; k < 6; ++k) se.inertia_xi.push_back(xi.middleRows(k * n, n));
  }
  return n;
}

// The floating frame, the mass properties and what the file says of the full model.
void ReadFrameAndMass(const h5::Reader& r, long n, Superelement& se) {
  const long N = long(se.interfaces.size());
  se.floating_frame.type = r.StringAttribute("/floating_frame", "type");
  RequireShape(r, "/floating_frame/origin", 3, -1);
  RequireShape(r, "/floating_frame/orientation", 3, 3);
  RequireShape(r, "/floating_frame/Phi_CB", 6, n);
  se.floating_frame.origin = r.Vector("/floating_frame/origin");
  se.floating_frame.orientation = r.Matrix("/floating_frame/orientation");
  se.floating_frame.Phi_CB = r.Matrix("/floating_frame/Phi_CB");
  if (r.Exists("/floating_frame/cardona_weights")) {
    RequireShape(r, "/floating_frame/cardona_weights", N, -1);
    se.floating_frame.cardona_weights = r.Vector("/floating_frame/cardona_weights");
  }

  se.mass_properties.mass = r.Scalar("/mass_properties/mass");
  RequireShape(r, "/mass_properties/center_of_mass", 3, -1);
  RequireShape(r, "/mass_properties/inertia_com", 3, 3);
  se.mass_properties.center_of_mass = r.Vector("/mass_properties/center_of_mass");
  se.mass_properties.inertia_com = r.Matrix("/mass_properties/inertia_com");

  se.n_full_dofs = r.IntAttribute("/full_model", "n_dofs");
  if (r.Exists("/full_model/rigid_couplings")) se.full_rigid_couplings = r.Strings("/full_model/rigid_couplings");
  if (r.Exists("/full_model/free_free_frequencies_hz")) {
    se.full_free_free_frequencies_hz = r.Vector("/full_model/free_free_frequencies_hz");
  }
}

// Per interface, the mesh nodes its coupling ties (ragged: the sets one after the other and N + 1
// offsets), each a node of the mesh's n_nodes.
std::vector<std::vector<int>> ReadInterfaceNodeSets(const h5::Reader& r, long n_nodes,
                                                    const std::vector<InterfaceNode>& interfaces) {
  std::vector<std::vector<int>> sets;
  const Eigen::VectorXi flat = r.IntVector("/visualization/interface_nodes");
  const Eigen::VectorXi offsets = r.IntVector("/visualization/interface_node_offsets");
  if (offsets.size() != long(interfaces.size()) + 1 || offsets[0] != 0 || offsets[offsets.size() - 1] != flat.size()) {
    throw InputError(r.path() + ": /visualization/interface_node_offsets: expected " +
                     std::to_string(interfaces.size() + 1) + " offsets from 0 to " + std::to_string(flat.size()));
  }
  for (long k = 0; k + 1 < offsets.size(); ++k) {
    if (offsets[k + 1] < offsets[k])
      throw InputError(r.path() + ": /visualization/interface_node_offsets: decreasing at " + std::to_string(k));
    std::vector<int> set(flat.data() + offsets[k], flat.data() + offsets[k + 1]);
    for (int node : set) {
      if (node < 0 || node >= n_nodes) {
        throw InputError(r.path() + ": /visualization/interface_nodes: node " + std::to_string(node) +
                         " of interface '" + interfaces[size_t(k)].name + "' is not a node of /visualization/nodes");
      }
    }
    sets.push_back(std::move(set));
  }
  return sets;
}

// The modal stresses on the mesh `v`, for n reduced coordinates.
ModalStress ReadStress(const h5::Reader& r, const Visualization& v, long n) {
  ModalStress st;
  st.method = r.StringAttribute("/stress", "method");
  const std::vector<hsize_t> shape = r.Shape("/stress/points");
  const long np = shape.empty() ? 0 : long(shape[0]);
  RequireShape(r, "/stress/points", np, 3);
  st.points = r.Matrix("/stress/points");
  RequireShape(r, "/stress/node", np, -1);
  st.node = r.IntVector("/stress/node");
  for (long p = 0; p < np; ++p) {
    if (st.node[p] < 0 || st.node[p] >= v.nodes.rows()) {
      throw InputError(r.path() + ": dataset /stress/node: entry " + std::to_string(p) + " = " +
                       std::to_string(st.node[p]) + " is not a node of /visualization/nodes");
    }
  }
  RequireShape(r, "/stress/modes", 6 * np, n);
  st.modes = r.FloatMatrix("/stress/modes");
  if (r.Exists("/stress/section_forces")) {
    RequireShape(r, "/stress/section_forces", 12 * v.cells.rows(), n);
    RequireShape(r, "/stress/element_axes", v.cells.rows(), 9);
    st.section_forces = r.FloatMatrix("/stress/section_forces");
    st.element_axes = r.Matrix("/stress/element_axes");
  }
  if (r.Exists("/stress/element_quadratic")) {
    RequireShape(r, "/stress/element_quadratic", v.cells.rows(), n * (n + 1) / 2);
    RequireShape(r, "/stress/point_element", np, -1);
    RequireShape(r, "/stress/element_axes", v.cells.rows(), 9);
    st.element_quadratic = r.FloatMatrix("/stress/element_quadratic");
    st.element_axes = r.Matrix("/stress/element_axes");
    st.point_element = r.IntVector("/stress/point_element");
    for (long p = 0; p < np; ++p) {
      if (st.point_element[p] < 0 || st.point_element[p] >= v.cells.rows()) {
        throw InputError(r.path() + ": dataset /stress/point_element: entry " + std::to_string(p) + " = " +
                         std::to_string(st.point_element[p]) + " is not a cell of /visualization/cells");
      }
    }
  }
  if (r.Exists("/stress/gradients") || r.Exists("/stress/element_quadratic")) {
    RequireShape(r, "/stress/material", 2, -1);
    if (r.Exists("/stress/gradients")) {
      RequireShape(r, "/stress/gradients", 9 * np, n);
      st.gradients = r.FloatMatrix("/stress/gradients");
    }
    const Eigen::VectorXd material = r.Vector("/stress/material");
    st.E = material[0];
    st.nu = material[1];
    if (!(st.E > 0) || !(st.nu > -1 && st.nu < 0.5)) {
      throw InputError(r.path() + ": dataset /stress/material: E and nu must be positive and in (-1, 0.5)");
    }
  }
  if (r.Exists("/stress/inertia_modes")) {
    RequireShape(r, "/stress/inertia_modes", 6 * np, kInertiaLoadCaseCount);
    st.inertia_modes = r.FloatMatrix("/stress/inertia_modes");
    if (r.Exists("/stress/inertia_section_forces")) {
      RequireShape(r, "/stress/inertia_section_forces", 12 * v.cells.rows(), kInertiaLoadCaseCount);
      st.inertia_section_forces = r.FloatMatrix("/stress/inertia_section_forces");
    }
  }
  return st;
}

// The mesh and the mode shapes on it, with the modal stresses when asked for.
void ReadVisualization(const h5::Reader& r, const SuperelementReadOptions& options, long n, Superelement& se) {
  Visualization v;
  const std::string cell_word = r.StringAttribute("/visualization", "cell_type");
  const std::optional<CellType> cell_type = KindOf<CellType>(cell_word);
  if (!cell_type) {
    throw InputError(r.path() + ": /visualization cell_type '" + cell_word +
                     "' is not a cell femb knows (known: " + JoinWords(WordsOf<CellType>()) + ")");
  }
  v.cell_type = *cell_type;
  v.dofs_per_node = int(r.IntAttribute("/visualization", "dofs_per_node"));
  v.nodes = r.Matrix("/visualization/nodes");
  v.cells = r.IntMatrix("/visualization/cells");
  RequireShape(r, "/visualization/shapes", v.nodes.rows() * v.dofs_per_node, n);
  v.shapes = r.Matrix("/visualization/shapes");
  if (r.Exists("/visualization/interface_nodes"))
    v.interface_nodes = ReadInterfaceNodeSets(r, long(v.nodes.rows()), se.interfaces);
  if (options.stress && r.Exists("/stress")) se.stress = ReadStress(r, v, n);
  se.visualization = std::move(v);
}

// Where the file came from and the reduction's stages' times.
void ReadProvenance(const h5::Reader& r, Provenance& p) {
  p.femb_version = r.StringAttribute("/provenance", "femb_version");
  p.input_file = r.StringAttribute("/provenance", "input_file");
  p.input_hash = r.StringAttribute("/provenance", "input_hash");
  p.element_type = r.StringAttribute("/provenance", "element_type");
  if (r.HasAttribute("/provenance", "reduction_method"))
    p.reduction_method = r.StringAttribute("/provenance", "reduction_method");
  p.n_nodes = r.IntAttribute("/provenance", "n_nodes");
  p.n_elements = r.IntAttribute("/provenance", "n_elements");
  std::vector<std::string> stages = r.Strings("/provenance/stages");
  Eigen::VectorXd seconds = r.Vector("/provenance/stage_seconds");
  for (size_t i = 0; i < stages.size() && long(i) < seconds.size(); ++i) {
    p.stage_seconds.emplace_back(stages[i], seconds[i]);
  }
}

}  // namespace

Superelement ReadSuperelementFile(const std::string& path, const SuperelementReadOptions& options) {
  h5::Reader r(path);
  RequireFormat(r);
  Superelement se;
  ReadHeader(r, se);
  const long n = ReadReduced(r, se);
  ReadFrameAndMass(r, n, se);
  if (options.visualization && r.Exists("/visualization")) ReadVisualization(r, options, n, se);
  if (r.Exists("/provenance")) ReadProvenance(r, se.provenance);
  return se;
}

}  // namespace femb
