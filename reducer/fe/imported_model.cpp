#include "reducer/fe/imported_model.h"

#include <unistd.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <unordered_map>

#include "formats/input_error.h"
#include "formats/skew.h"
#include "formats/vtk_cells.h"
#include "reducer/fe/beam_model.h"
#include "reducer/fe/solid_element.h"
#include "reducer/fe/solid_model.h"
#include "reducer/mesh/abaqus_mesh.h"
#include "reducer/mesh/meshio_import.h"
#include "reducer/mesh/node_selection.h"
#include "reducer/reduction/craig_bampton.h"
namespace femb {
namespace {

// Where each imported DOF sits: its mesh node (full_node), each mesh node's DOF per component
// (full_dof, -1: none), and how many are rotations. Every node of the matrices must be a node of
// the geometry file.
struct ImportedDofs {
  std::vector<int> full_node;
  std::vector<std::array<int, 6>> full_dof;
  int rotational = 0;
};

ImportedDofs MapImportedDofs(const PartSpec& part, const ForeignMesh& geometry, const ImportedMatrices& im) {
  const long n_nodes = geometry.nodes.rows(), n_full = long(im.node.size());
  ImportedDofs d;
  std::unordered_map<long, int> index_of;
  for (long s = 0; s < n_nodes; ++s) index_of[geometry.ids[size_t(s)]] = int(s);
  d.full_node.resize(static_cast<size_t>(n_full));  // mesh node of each imported DOF
  d.full_dof.resize(static_cast<size_t>(n_nodes));
  for (auto& f : d.full_dof) f.fill(-1);
  for (long r = 0; r < n_full; ++r) {
    auto it = index_of.find(im.node[size_t(r)]);
    if (it == index_of.end()) {
      throw InputError(part.matrices.where + ": node " + std::to_string(im.node[size_t(r)]) +
                       " of the matrices is not in " + part.solid.file + " (its node labels run " +
                       std::to_string(geometry.ids.front()) + " .. " + std::to_string(geometry.ids.back()) +
                       "): the geometry file must be the mesh the matrices were exported from");
    }
    d.full_node[size_t(r)] = it->second;
    d.full_dof[size_t(it->second)][size_t(im.component[size_t(r)])] = int(r);
    d.rotational += im.component[size_t(r)] >= 3;
  }
  return d;
}

// The geometry's cells as a volume mesh when they are solids femb knows (for selections inside
// the volume and interpolation); null otherwise.
std::shared_ptr<SolidMesh> SolidVolume(const ForeignMesh& geometry) {
  const std::optional<SolidType> type = SolidTypeOf(geometry.cell_type);
  if (!type) return nullptr;
  auto volume = std::make_shared<SolidMesh>();
  volume->nodes = geometry.nodes;
  volume->cells = geometry.cells;
  volume->type = *type;
  return volume;
}

// Model DOFs: the imported DOFs of nodes in no RBE2 set (file order), then 6 per RBE2 interface,
// into model.dof_point, dof_component, dof_node; model_of (per imported DOF, -1 in an RBE2 set) and
// base (per interface, its first model DOF, -1 if not RBE2). The map T (imported -> model):
// u_s = u_k + theta_k x (x_s - x_k) = u_k - (x_s - x_k)~ theta_k, theta_s = theta_k.
SparseMatrix RigidCouplingMap(const PartSpec& part, const ForeignMesh& geometry, const ImportedMatrices& im,
                              const ImportedDofs& d, const std::vector<int>& owner, std::vector<int>& model_of,
                              std::vector<int>& base, FeModel& model) {
  const long n_full = long(im.node.size());
  const std::vector<int>& full_node = d.full_node;
  auto rbe2 = [&](long s) {
    return owner[size_t(s)] >= 0 && part.interfaces[size_t(owner[size_t(s)])].coupling == Coupling::kRbe2;
  };
  model_of.assign(static_cast<size_t>(n_full), -1);
  int n_model = 0;
  for (long r = 0; r < n_full; ++r) {
    if (!rbe2(full_node[size_t(r)])) {
      model_of[size_t(r)] = n_model++;
      model.dof_point.push_back(geometry.nodes.row(full_node[size_t(r)]).transpose());
      model.dof_component.push_back(im.component[size_t(r)]);
      model.dof_node.push_back(int(full_node[size_t(r)]));
    }
  }
  base.assign(part.interfaces.size(), -1);
  for (size_t k = 0; k < part.interfaces.size(); ++k) {
    if (part.interfaces[k].coupling != Coupling::kRbe2) continue;
    base[k] = n_model;
    for (int c = 0; c < 6; ++c) {
      model.dof_point.push_back(model.interface_positions[k]);
      model.dof_component.push_back(c);
      model.dof_node.push_back(int(geometry.nodes.rows() + long(k)));
    }
    n_model += 6;
  }
  std::vector<Eigen::Triplet<double>> t;
  for (long r = 0; r < n_full; ++r) {
    const long s = full_node[size_t(r)];
    const int c = im.component[size_t(r)];
    if (!rbe2(s)) {
      t.emplace_back(int(r), model_of[size_t(r)], 1.0);
      continue;
    }
    const size_t k = size_t(owner[size_t(s)]);
    t.emplace_back(int(r), base[k] + c, 1.0);
    if (c < 3) {
      const Eigen::Matrix3d arm =
          -Skew<double>(Eigen::Vector3d(geometry.nodes.row(s).transpose() - model.interface_positions[k]));
      for (int j = 0; j < 3; ++j)
        if (arm(c, j) != 0.0) t.emplace_back(int(r), base[k] + 3 + j, arm(c, j));
    }
  }
  SparseMatrix T(n_full, n_model);
  T.setFromTriplets(t.begin(), t.end());
  return T;
}

// The interfaces' couplings: an RBE2 interface's six model DOFs; an RBE3 interface's weights on
// the translations of its set's nodes.
void InterfaceCouplings(const PartSpec& part, const ForeignMesh& geometry, const ImportedDofs& d,
                        const std::vector<std::vector<int>>& sets, const std::vector<int>& model_of,
                        const std::vector<int>& base, int n_model, FeModel& model) {
  const std::vector<std::array<int, 6>>& full_dof = d.full_dof;
  for (size_t k = 0; k < part.interfaces.size(); ++k) {
    std::vector<FullDof> dofs;
    SparseMatrix W(0, n_model);
    if (base[k] >= 0) {
      for (int c = 0; c < 6; ++c) dofs.push_back({base[k] + c});
    } else {
      std::vector<int> nodes;
      for (int s : sets[k]) {
        const auto& f = full_dof[size_t(s)];
        if (f[0] >= 0 && f[1] >= 0 && f[2] >= 0) nodes.push_back(s);
      }
      const Eigen::MatrixXd w = Rbe3Weights(geometry.nodes, nodes, model.interface_positions[k],
                                            part.interfaces[k].where, part.interfaces[k].name);
      std::vector<Eigen::Triplet<double>> entries;
      for (size_t a = 0; a < nodes.size(); ++a)
        for (int c = 0; c < 3; ++c)
          for (int i = 0; i < 6; ++i)
            entries.emplace_back(i, model_of[size_t(full_dof[size_t(nodes[a])][size_t(c)])], w(i, long(3 * a + c)));
      W.resize(6, n_model);
      W.setFromTriplets(entries.begin(), entries.end());
    }
    model.interface_dofs.push_back(dofs);
    model.interface_weights.push_back(W);
  }
}

// The body must float: K R = 0 for the rigid-body fields R (to the round-off of the export), and
// have a mass. Returns the residual and the mass for the progress line.
std::pair<double, double> CheckFloats(const PartSpec& part, const FeModel& model) {
  const Eigen::MatrixXd R = RigidFields(model);
  const Eigen::MatrixXd KR = model.K * R;
  double k_scale = 0.0;
  for (int j = 0; j < model.K.outerSize(); ++j) k_scale = std::max(k_scale, model.K.coeff(j, j));
  double residual = 0.0;
  for (int j = 0; j < 6; ++j)
    residual = std::max(residual, KR.col(j).cwiseAbs().maxCoeff() / (k_scale * R.col(j).cwiseAbs().maxCoeff()));
  const double mass = (R.col(0).transpose() * model.M * R.col(0)).value();
  if (residual > 1e-6) {
    throw InputError(part.matrices.where +
                     ": the stiffness resists a rigid-body motion (|K r| = " + ShortNumber(residual) +
                     " of the largest diagonal): the export kept boundary conditions or grounded springs; export the "
                     "free part");
  }
  if (!(mass > 0))
    throw InputError(part.matrices.where + ": the mass matrix gives the part no mass (" + ShortNumber(mass) + ")");
  return {residual, mass};
}

// The mesh of --export-matrices as an Abaqus deck: node labels 1..n = the matrices' node numbers.
// Abaqus/CAE's layout (*Part, *Assembly, *Instance; the sets in the part) for the Abaqus formats,
// which Abaqus and readers of its decks (Exudyn's FEMinterface) take; a flat deck (*NODE,
// *ELEMENT at the top) for the others, which CalculiX reads.
void WriteDeck(const std::string& path, const std::string& name, const Eigen::MatrixXd& nodes,
               const Eigen::MatrixXi& cells, const std::string& element,
               const std::map<std::string, std::vector<int>>& node_sets, bool parts) {
  const std::string tmp = path + ".tmp" + std::to_string(::getpid());
  std::ofstream out(tmp);
  out.precision(13);  // CalculiX reads at most 20 characters per field ("-7.347880794884e-18" is 19)
  out << "** " << name << ": mesh of femb-reduce --export-matrices (node labels = matrix node numbers)\n";
  if (parts) out << "*Heading\n" << name << "\n*Part, name=" << name << '\n';
  out << (parts ? "*Node\n" : "*NODE\n");
  for (long s = 0; s < nodes.rows(); ++s)
    out << s + 1 << ", " << nodes(s, 0) << ", " << nodes(s, 1) << ", " << nodes(s, 2) << '\n';
  out << (parts ? "*Element, type=" : "*ELEMENT, TYPE=") << element << (parts ? ", elset=EALL\n" : ", ELSET=EALL\n");
  // Abaqus takes at most 16 entries on a data line (a trailing comma continues it); CalculiX
  // reads the flat deck's one line per element.
  const long per_line = parts ? 16 : cells.cols() + 1;
  for (long e = 0; e < cells.rows(); ++e) {
    out << e + 1;
    for (long a = 0; a < cells.cols(); ++a) out << ((a + 1) % per_line == 0 ? ",\n" : ", ") << cells(e, a) + 1;
    out << '\n';
  }
  for (const auto& [set_name, set] : node_sets) {
    out << (parts ? "*Nset, nset=" : "*NSET, NSET=") << set_name << '\n';
    for (size_t i = 0; i < set.size(); ++i) out << set[i] + 1 << (i % 16 == 15 || i + 1 == set.size() ? "\n" : ", ");
  }
  if (parts) {
    out << "*End Part\n*Assembly, name=Assembly\n*Instance, name=" << name << "-1, part=" << name
        << "\n*End Instance\n*End Assembly\n";
  }
  if (!out) throw InputError(std::filesystem::path(path).parent_path().string() + ": cannot write " + path);
  out.close();
  std::filesystem::rename(tmp, path);
}

}  // namespace

FeModel BuildImportedModel(const PartSpec& part, const ProgressFn& progress) {
  Stopwatch clock;
  const ForeignMesh geometry = ReadImportedGeometry(part.solid.file, part.matrices.instance, part.solid.where);
  const long n_nodes = geometry.nodes.rows();
  const Eigen::Vector3d lo = geometry.nodes.colwise().minCoeff(), hi = geometry.nodes.colwise().maxCoeff();
  CheckPartSize(part, (hi - lo).norm(), part.solid.where + " (" + part.solid.file + ")");
  if (progress) {
    progress("geometry", clock.Seconds(),
             std::to_string(n_nodes) + " nodes, " + std::to_string(geometry.cells.rows()) + " " +
                 Name(geometry.cell_type) + " cells from " + part.solid.file);
  }

  clock.Restart();
  const ImportedMatrices im = ReadImportedMatrices(part.matrices);
  const long n_full = long(im.node.size());
  const ImportedDofs d = MapImportedDofs(part, geometry, im);
  if (progress) {
    progress("matrices", clock.Seconds(),
             std::to_string(n_full) + " DOFs (" + std::to_string(d.rotational) + " rotational), K " +
                 std::to_string(im.K.nonZeros()) + " entries (" + im.stored + " in the file), M " +
                 std::to_string(im.M.nonZeros()) + " entries, " + Name(part.matrices.format));
  }

  // Interfaces: node sets by name or by geometry; only nodes that carry DOFs of the matrices take
  // part (a mesh may have unused nodes).
  clock.Restart();
  FeModel model;
  const std::shared_ptr<SolidMesh> volume = SolidVolume(geometry);
  const InterfaceNodes interface_nodes = ResolveInterfaceNodes(
      part, geometry.nodes, geometry.node_sets, volume.get(), part.solid.file,
      [&](int s) {
        for (int c = 0; c < 6; ++c)
          if (d.full_dof[size_t(s)][size_t(c)] >= 0) return true;
        return false;
      },
      "has a DOF in the matrices");
  for (size_t k = 0; k < part.interfaces.size(); ++k) {
    model.interface_names.push_back(part.interfaces[k].name);
    model.interface_positions.push_back(interface_nodes.positions[k]);
  }
  model.interface_node_sets = interface_nodes.sets;
  std::vector<int> model_of, base;
  const SparseMatrix T = RigidCouplingMap(part, geometry, im, d, interface_nodes.owner, model_of, base, model);
  const int n_model = int(T.cols());
  const SparseMatrix Tt = T.transpose();
  model.K = SparseMatrix(Tt * im.K * T);
  model.M = SparseMatrix(Tt * im.M * T);
  model.K.prune(0.0);
  model.M.prune(0.0);
  InterfaceCouplings(part, geometry, d, interface_nodes.sets, model_of, base, n_model, model);
  // Mesh DOFs (3 per geometry node: the translations; zero for a node without them) = S T q.
  std::vector<Eigen::Triplet<double>> pick;
  for (long s = 0; s < n_nodes; ++s)
    for (int c = 0; c < 3; ++c)
      if (d.full_dof[size_t(s)][size_t(c)] >= 0)
        pick.emplace_back(int(3 * s + c), d.full_dof[size_t(s)][size_t(c)], 1.0);
  SparseMatrix S(3 * n_nodes, n_full);
  S.setFromTriplets(pick.begin(), pick.end());
  model.mesh_map = SparseMatrix(S * T);
  model.full_map = T;
  model.dofs_per_node = 3;
  model.nodes = geometry.nodes;
  model.cells = geometry.cells;
  model.cell_type = geometry.cell_type;
  model.element_type = std::string("imported ") + Name(part.matrices.format);
  if (volume) model.interpolate_at = SolidInterpolation(volume, model.mesh_map);
  const auto [residual, mass] = CheckFloats(part, model);
  if (progress) {
    progress("couplings", clock.Seconds(),
             std::to_string(part.interfaces.size()) + " interfaces (" + interface_nodes.summary + "), " +
                 std::to_string(n_model) + " model DOFs; rigid-body residual " + ShortNumber(residual) + ", mass " +
                 ShortNumber(mass));
  }
  return model;
}

std::vector<std::string> ExportPartMatrices(const PartSpec& part, MatrixFormat format, const std::string& directory,
                                            const ProgressFn& progress) {
  if (part.type == PartType::kImported)
    throw InputError(part.file + ": --export-matrices: the part's matrices are imported already");
  Stopwatch clock;
  SparseMatrix K, M;
  std::vector<long> node;
  std::vector<int> component;
  Eigen::MatrixXd nodes;
  Eigen::MatrixXi cells;
  std::string element;  // Abaqus element type
  std::map<std::string, std::vector<int>> node_sets;
  if (part.type == PartType::kSolid) {
    const SolidMesh mesh = MeshSolidPart(part);
    SolidDofMap map;
    const int n = int(mesh.nodes.rows());
    map.n_dofs = 3 * n;
    map.model_node.resize(size_t(n));
    map.arm.assign(size_t(n), Eigen::Matrix3d::Zero());
    for (int s = 0; s < n; ++s) {
      map.model_node[size_t(s)] = s;
      map.first_dof.push_back(3 * s);
      map.dofs.push_back(3);
    }
    AssembleSolid(mesh, part.material, map, &K, &M);
    for (int s = 0; s < n; ++s)
      for (int c = 0; c < 3; ++c) {
        node.push_back(s + 1);
        component.push_back(c);
      }
    nodes = mesh.nodes;
    cells = ToVtkOrder(CellOf(mesh.type), mesh.cells);  // VTK order = Abaqus order for these
    const std::map<SolidType, std::string> names = {{SolidType::kTet4, "C3D4"},
                                                    {SolidType::kTet10, "C3D10"},
                                                    {SolidType::kHex8, "C3D8"},
                                                    {SolidType::kHex20, "C3D20"}};
    element = names.at(mesh.type);
    node_sets = mesh.node_sets;
  } else {
    const FeModel model = BuildBeamModel(part);
    K = model.K;
    M = model.M;
    for (long s = 0; s < model.n_nodes(); ++s)
      for (int c = 0; c < 6; ++c) {
        node.push_back(s + 1);
        component.push_back(c);
      }
    nodes = model.nodes;
    cells = model.cells;
    element = "B31";
    for (size_t p = 0; p < part.beam.point_names.size(); ++p) node_sets[part.beam.point_names[p]] = {int(p)};
  }
  std::vector<std::string> written = WriteMatrices(format, K, M, node, component, directory, part.name);
  const std::string mesh_path = (std::filesystem::path(directory) / (part.name + ".inp")).string();
  const bool abaqus = format == MatrixFormat::kAbaqus || format == MatrixFormat::kAbaqusCoordinate;
  WriteDeck(mesh_path, part.name, nodes, cells, element, node_sets, abaqus);
  written.push_back(mesh_path);
  if (progress) {
    progress("export", clock.Seconds(),
             std::to_string(node.size()) + " DOFs, " + std::to_string(cells.rows()) + " " + element + " elements, " +
                 Name(format) + " matrices and " + mesh_path);
  }
  return written;
}
}  // namespace femb
