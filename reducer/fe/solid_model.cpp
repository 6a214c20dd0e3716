#include "reducer/fe/solid_model.h"

#include <Eigen/Dense>
#include <algorithm>
#include <map>
#include <memory>
#include <numeric>
#include <optional>

#include "formats/input_error.h"
#include "formats/skew.h"
#include "reducer/fe/connectivity.h"
#include "reducer/fe/solid_element.h"
#include "reducer/linalg/interior_solver.h"
#include "reducer/linalg/shared_columns.h"
#include "reducer/mesh/gmsh_mesher.h"
#include "reducer/mesh/meshio_import.h"
#include "reducer/mesh/node_selection.h"

namespace femb {
namespace {

// Reference coordinates of x in element e, or false when outside (1e-9).
bool Locate(const SolidMesh& mesh, int e, const Eigen::Vector3d& x, Eigen::Vector3d* xi) {
  return LocateInCell(mesh.type, mesh.nodes, mesh.cells, e, x, xi);
}

// The sparsity of the assembled K and M, column block by model node: the model-node graph in CSR
// form (neighbours, including the node itself, sorted by first DOF: model nodes are numbered in
// DOF order, so sorting by number sorts the rows), and per neighbour the offset of its rows in
// the column. Every column of model node P has the same rows: all DOFs of each neighbour Q for K;
// for M only the like component when P and Q are both free 3-DOF nodes (consistent mass couples
// like components), all DOFs of Q otherwise. Only the columns held (a rank's share) have rows: a
// node none of whose DOFs is held has no neighbours here.
struct SolidPattern {
  std::vector<long> start;               ///< per model node, its first entry in `adjacent` (n + 1)
  std::vector<int> adjacent;             ///< neighbours, ascending
  std::vector<long> prefix_k, prefix_m;  ///< per entry of `adjacent`: its rows' offset in a column
  std::vector<long> length_k, length_m;  ///< per model node: rows in each of its columns
  /// 1 when a column of P holds only the like component of Q in M, else Q's DOFs.
  static int MassRows(const SolidDofMap& map, int P, int Q) {
    return map.dofs[P] == 3 && map.dofs[Q] == 3 ? 1 : map.dofs[Q];
  }
};

// Whether this process holds a column of model node P.
bool HoldsNode(const SolidDofMap& map, const ColumnShare& held, int P) {
  const long first = map.first_dof[P];
  return held.whole() || (first < held.first + held.count && first + map.dofs[P] > held.first);
}

SolidPattern Pattern(const SolidMesh& mesh, const SolidDofMap& map, const ColumnShare& held) {
  const int per = SolidNodeCount(mesh.type);
  const long n_cells = mesh.cells.rows();
  const int n_model_nodes = int(map.first_dof.size());
  SolidPattern g;
  std::vector<std::vector<int>> cells_of(n_model_nodes);
  for (long e = 0; e < n_cells; ++e)
    for (int a = 0; a < per; ++a) {
      const int P = map.model_node[mesh.cells(e, a)];
      if (!HoldsNode(map, held, P)) continue;
      std::vector<int>& c = cells_of[P];
      if (c.empty() || c.back() != int(e)) c.push_back(int(e));
    }
  std::vector<long>& start = g.start;
  std::vector<int>& adjacent = g.adjacent;
  start.assign(size_t(n_model_nodes) + 1, 0);
  std::vector<int> scratch;
  for (int P = 0; P < n_model_nodes; ++P) {
    scratch.clear();
    for (int e : cells_of[P])
      for (int a = 0; a < per; ++a) scratch.push_back(map.model_node[mesh.cells(e, a)]);
    std::sort(scratch.begin(), scratch.end());
    scratch.erase(std::unique(scratch.begin(), scratch.end()), scratch.end());
    adjacent.insert(adjacent.end(), scratch.begin(), scratch.end());
    start[P + 1] = long(adjacent.size());
  }
  cells_of = {};
  g.prefix_k.resize(adjacent.size()), g.prefix_m.resize(adjacent.size());
  g.length_k.resize(size_t(n_model_nodes)), g.length_m.resize(size_t(n_model_nodes));
  double entries_k = 0;
  for (int P = 0; P < n_model_nodes; ++P) {
    long lk = 0, lm = 0;
    for (long k = start[P]; k < start[P + 1]; ++k) {
      g.prefix_k[k] = lk;
      g.prefix_m[k] = lm;
      lk += map.dofs[adjacent[k]];
      lm += SolidPattern::MassRows(map, P, adjacent[k]);
    }
    g.length_k[P] = lk;
    g.length_m[P] = lm;
    entries_k += double(lk) * map.dofs[P];
  }
  if (entries_k > 2e9) throw InputError("mesh too large: more than 2^31 stiffness entries");
  return g;
}

// An n x n matrix with the pattern's entries for K (or M with `mass`) in the held columns,
// zero-filled: built column by column, no triplet list.
void ShapeMatrix(const SolidDofMap& map, const SolidPattern& g, bool mass, const ColumnShare& held, SparseMatrix* A) {
  const long n = map.n_dofs;
  const int n_model_nodes = int(map.first_dof.size());
  const std::vector<long>& start = g.start;
  const std::vector<int>& adjacent = g.adjacent;
  const std::vector<long>& length_k = g.length_k;
  const std::vector<long>& length_m = g.length_m;
  const auto mass_rows = [&](int P, int Q) { return SolidPattern::MassRows(map, P, Q); };
  *A = SparseMatrix(n, n);
  long total = 0;
  for (int P = 0; P < n_model_nodes; ++P)
    for (int d = 0; d < map.dofs[P]; ++d)
      if (held.Holds(map.first_dof[P] + d)) total += mass ? length_m[P] : length_k[P];
  A->resizeNonZeros(total);
  int* outer = A->outerIndexPtr();
  int* inner = A->innerIndexPtr();
  long p = 0;
  for (int P = 0; P < n_model_nodes; ++P)
    for (int d = 0; d < map.dofs[P]; ++d) {
      outer[map.first_dof[P] + d] = int(p);
      if (!held.Holds(map.first_dof[P] + d)) continue;
      for (long k = start[P]; k < start[P + 1]; ++k) {
        const int Q = adjacent[k];
        if (mass && mass_rows(P, Q) == 1) {
          inner[p++] = map.first_dof[Q] + d;
        } else {
          for (int c = 0; c < map.dofs[Q]; ++c) inner[p++] = map.first_dof[Q] + c;
        }
      }
    }
  outer[n] = int(p);
  std::fill(A->valuePtr(), A->valuePtr() + p, 0.0);
}

}  // namespace

long AssembleSolid(const SolidMesh& mesh, const MaterialSpec& material, const SolidDofMap& map, SparseMatrix* K,
                   SparseMatrix* M, const ColumnShare& held) {
  const int per = SolidNodeCount(mesh.type);
  const long n_cells = mesh.cells.rows();
  const SolidPattern g = Pattern(mesh, map, held);
  ShapeMatrix(map, g, false, held, K);
  ShapeMatrix(map, g, true, held, M);
  const std::vector<long>& start = g.start;
  const std::vector<int>& adjacent = g.adjacent;
  const std::vector<long>& prefix_k = g.prefix_k;
  const std::vector<long>& prefix_m = g.prefix_m;
  const auto mass_rows = [&](int P, int Q) { return SolidPattern::MassRows(map, P, Q); };
  double* kv = K->valuePtr();
  double* mv = M->valuePtr();
  const int* k_outer = K->outerIndexPtr();
  const int* m_outer = M->outerIndexPtr();
  Eigen::MatrixXd X(per, 3);
  std::vector<int> nodes;         // the element's model nodes, ascending
  std::vector<int> local_offset;  // their first column in the element's model DOFs
  std::vector<int> a_of;          // uncoupled element: element node of the i-th model node
  Eigen::MatrixXd Te, Ke, Me;
  long assembled = 0;
  for (long e = 0; e < n_cells; ++e) {
    if (!held.whole()) {
      bool touches = false;
      for (int a = 0; a < per && !touches; ++a) touches = HoldsNode(map, held, map.model_node[mesh.cells(e, a)]);
      if (!touches) continue;
    }
    ++assembled;
    for (int a = 0; a < per; ++a) X.row(a) = mesh.nodes.row(mesh.cells(e, a));
    const SolidElementMatrices em = ComputeSolidElement(mesh.type, X, material, e);
    nodes.clear();
    for (int a = 0; a < per; ++a) nodes.push_back(map.model_node[mesh.cells(e, a)]);
    std::sort(nodes.begin(), nodes.end());
    nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
    local_offset.assign(nodes.size() + 1, 0);
    for (size_t i = 0; i < nodes.size(); ++i) local_offset[i + 1] = local_offset[i] + map.dofs[nodes[i]];
    const int n_e = local_offset.back();
    // Element matrices on the model DOFs: T_e^T K_e T_e (T_e = 1 when no node is coupled).
    const bool coupled = n_e != 3 * per || int(nodes.size()) != per;
    const Eigen::MatrixXd* ke = &em.K;
    const Eigen::MatrixXd* me = &em.M;
    if (coupled) {
      Te.setZero(3 * per, n_e);
      for (int a = 0; a < per; ++a) {
        const int s = mesh.cells(e, a);
        const int P = map.model_node[s];
        const int col = local_offset[std::lower_bound(nodes.begin(), nodes.end(), P) - nodes.begin()];
        Te.block<3, 3>(3 * a, col).setIdentity();
        if (map.dofs[P] == 6) Te.block<3, 3>(3 * a, col + 3) = map.arm[s];
      }
      Ke = Te.transpose() * em.K * Te;
      Me = Te.transpose() * em.M * Te;
      ke = &Ke;
      me = &Me;
    } else {
      // Uncoupled: element node a_of[i] is the i-th model node in ascending order.
      a_of.resize(per);
      for (int a = 0; a < per; ++a) {
        const long i = std::lower_bound(nodes.begin(), nodes.end(), map.model_node[mesh.cells(e, a)]) - nodes.begin();
        a_of[i] = a;
      }
    }
    // Scatter: column DOF (P, d), row DOF (Q, c).
    for (size_t i = 0; i < nodes.size(); ++i) {
      const int P = nodes[i];
      if (!HoldsNode(map, held, P)) continue;
      const int* first = adjacent.data() + start[P];
      const int* last = adjacent.data() + start[P + 1];
      for (size_t j = 0; j < nodes.size(); ++j) {
        const int Q = nodes[j];
        const long k = start[P] + (std::lower_bound(first, last, Q) - first);
        const bool diagonal_mass = mass_rows(P, Q) == 1;
        for (int d = 0; d < map.dofs[P]; ++d) {
          if (!held.Holds(map.first_dof[P] + d)) continue;
          // Local column of (P, d) and rows of Q in the element matrices; for an uncoupled
          // element the local numbering is the element's node order, not the sorted one.
          int col_local, row_local;
          if (coupled) {
            col_local = local_offset[i] + d;
            row_local = local_offset[j];
          } else {
            col_local = 3 * a_of[i] + d;
            row_local = 3 * a_of[j];
          }
          const long kc = k_outer[map.first_dof[P] + d] + prefix_k[k];
          for (int c = 0; c < map.dofs[Q]; ++c) kv[kc + c] += (*ke)(row_local + c, col_local);
          const long mc = m_outer[map.first_dof[P] + d] + prefix_m[k];
          if (diagonal_mass) {
            mv[mc] += (*me)(row_local + d, col_local);
          } else {
            for (int c = 0; c < map.dofs[Q]; ++c) mv[mc + c] += (*me)(row_local + c, col_local);
          }
        }
      }
    }
  }
  return assembled;
}

// The area-weighted centroid of the boundary faces whose corners all lie in `set` (flat facets
// through the corners; a face met twice is inside the part and left out): the default point of
// a solid interface. For a bore it lies on the axis, where the plain mean of the nodes does not
// (an unstructured mesh is denser on one side: 0.2 mm off on a 50 mm bar's face). None when
// the set has no such face (scattered nodes).
std::optional<Eigen::Vector3d> SurfaceCentroid(const SolidMesh& mesh, const std::vector<int>& set) {
  std::vector<char> in(size_t(mesh.nodes.rows()), 0);
  for (int n : set) in[size_t(n)] = 1;
  static const std::vector<std::vector<int>> kTetFaces = {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}};
  static const std::vector<std::vector<int>> kHexFaces = {{0, 1, 2, 3}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                                          {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  const bool tet = mesh.type == SolidType::kTet4 || mesh.type == SolidType::kTet10;
  const auto& faces = tet ? kTetFaces : kHexFaces;
  std::map<std::vector<int>, std::pair<int, std::vector<int>>> found;  // sorted corners -> (count, corners)
  for (Eigen::Index c = 0; c < mesh.cells.rows(); ++c) {
    for (const std::vector<int>& f : faces) {
      std::vector<int> corners;
      bool all = true;
      for (int local : f) {
        const int node = mesh.cells(c, local);
        all &= in[size_t(node)] != 0;
        corners.push_back(node);
      }
      if (!all) continue;
      std::vector<int> key = corners;
      std::sort(key.begin(), key.end());
      auto& entry = found[key];
      entry.first += 1;
      entry.second = corners;
    }
  }
  double area = 0.0;
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  for (const auto& [key, entry] : found) {
    if (entry.first != 1) continue;
    const std::vector<int>& v = entry.second;
    for (size_t t = 1; t + 1 < v.size(); ++t) {  // fan of triangles
      const Eigen::Vector3d a = mesh.nodes.row(v[0]).transpose(), b = mesh.nodes.row(v[t]).transpose(),
                            d = mesh.nodes.row(v[t + 1]).transpose();
      const double A = 0.5 * (b - a).cross(d - a).norm();
      area += A;
      moment += A * (a + b + d) / 3.0;
    }
  }
  if (!(area > 0)) return std::nullopt;
  return moment / area;
}

InterfaceNodes ResolveInterfaceNodes(const PartSpec& part, const Eigen::MatrixXd& nodes,
                                     const std::map<std::string, std::vector<int>>& node_sets, const SolidMesh* volume,
                                     const std::string& mesh_name, const std::function<bool(int)>& keep,
                                     const std::string& keep_reason) {
  InterfaceNodes out;
  out.sets.resize(part.interfaces.size());
  out.owner.assign(static_cast<size_t>(nodes.rows()), -1);
  for (size_t k = 0; k < part.interfaces.size(); ++k) {
    const InterfaceSpec& i = part.interfaces[k];
    std::vector<int> set;
    if (i.select) {
      set = SelectNodes(*i.select, nodes, i.name);
    } else {
      auto found = node_sets.find(i.group);
      if (found == node_sets.end()) {
        std::string known;
        for (const auto& [name, _] : node_sets) known += (known.empty() ? "" : ", ") + name;
        throw InputError(i.where + ": interface '" + i.name + "': node set '" + i.group + "' not found in " +
                         mesh_name + " (known: " + (known.empty() ? "none" : known) +
                         "; or pick the nodes by geometry with 'select')");
      }
      if (found->second.empty())
        throw InputError(i.where + ": interface '" + i.name + "': node set '" + i.group + "' is empty");
      set = found->second;
    }
    std::vector<int>& used = out.sets[k];
    for (int s : set)
      if (!keep || keep(s)) used.push_back(s);
    if (used.empty()) {
      throw InputError(i.where + ": interface '" + i.name + "': none of its " + std::to_string(set.size()) + " nodes " +
                       keep_reason);
    }
    const std::string source =
        i.select ? std::string("the ") + Name(i.select->shape) + " selection" : "node set '" + i.group + "'";
    out.summary += (k ? ", " : "") + i.name + ": " + std::to_string(used.size()) + " nodes " +
                   (i.select ? std::string("by ") + Name(i.select->shape) : "of set '" + i.group + "'");
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (int s : used) {
      if (out.owner[size_t(s)] >= 0) {
        throw InputError(i.where + ": interface '" + i.name + "': " + source + " shares nodes with interface '" +
                         part.interfaces[size_t(out.owner[size_t(s)])].name + "' (couplings must not overlap)");
      }
      out.owner[size_t(s)] = int(k);
      centroid += nodes.row(s).transpose();
    }
    centroid /= double(used.size());
    if (volume) {
      if (const std::optional<Eigen::Vector3d> surface = SurfaceCentroid(*volume, used)) centroid = *surface;
    }
    out.positions.push_back(i.location ? *i.location : centroid);
  }
  return out;
}

namespace {

// A node set's centroid c and the matrix A = sum (|r_i|^2 1 - r_i r_i^T), r_i = x_i - c (the
// set's polar moment about c); throws unless the set has at least 3 nodes not on one line: a
// coupling on fewer leaves the rotation about their line (or point) free, with no stiffness (a
// rigid coupling: the interface's rotation and the part's turn about it; K_ii singular) or
// undetermined (a distributing one).
struct PolarMoment {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
};
PolarMoment CheckedPolarMoment(const Eigen::MatrixXd& nodes, const std::vector<int>& set, const char* coupling,
                               const std::string& where, const std::string& name) {
  const int ns = int(set.size());
  PolarMoment p;
  for (int node : set) p.centroid += nodes.row(node).transpose();
  p.centroid /= std::max(ns, 1);
  for (int node : set) {
    const Eigen::Vector3d r = nodes.row(node).transpose() - p.centroid;
    p.A += r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose();
  }
  if (ns < 3 || std::abs(p.A.determinant()) < 1e-12 * std::pow(p.A.trace(), 3)) {
    throw InputError(where + ": interface '" + name + "': an " + coupling + " coupling needs at least 3 nodes not on " +
                     "one line (it ties " +
                     (ns == 1 ? std::string("1 node: the rotations about it would be free)")
                              : std::to_string(ns) + " nodes on one line: the rotation about it would be free)"));
  }
  return p;
}

}  // namespace

Eigen::MatrixXd Rbe3Weights(const Eigen::MatrixXd& nodes, const std::vector<int>& set, const Eigen::Vector3d& point,
                            const std::string& where, const std::string& name) {
  const int ns = int(set.size());
  const PolarMoment p = CheckedPolarMoment(nodes, set, "RBE3", where, name);
  const Eigen::Matrix3d Ainv = p.A.inverse();
  const Eigen::Vector3d& c = p.centroid;
  const Eigen::Vector3d d = point - c;
  Eigen::MatrixXd W = Eigen::MatrixXd::Zero(6, 3 * ns);
  for (int a = 0; a < ns; ++a) {
    const Eigen::Vector3d r = nodes.row(set[a]).transpose() - c;
    const Eigen::Matrix3d Wtheta = Ainv * Skew<double>(r);
    W.block<3, 3>(3, 3 * a) = Wtheta;
    W.block<3, 3>(0, 3 * a) = Eigen::Matrix3d::Identity() / ns - Skew<double>(d) * Wtheta;
  }
  return W;
}

std::function<std::optional<SparseMatrix>(const Eigen::Vector3d&)> SolidInterpolation(
    std::shared_ptr<const SolidMesh> mesh, const SparseMatrix& T) {
  return [mesh, T](const Eigen::Vector3d& x) -> std::optional<SparseMatrix> {
    const int per = SolidNodeCount(mesh->type);
    for (int e = 0; e < mesh->cells.rows(); ++e) {
      Eigen::Vector3d xi;
      if (!Locate(*mesh, e, x, &xi)) continue;
      Eigen::VectorXd N;
      Eigen::MatrixXd dN;
      SolidShapeFunctions(mesh->type, xi, &N, &dN);
      Eigen::MatrixXd X(per, 3);
      for (int a = 0; a < per; ++a) X.row(a) = mesh->nodes.row(mesh->cells(e, a));
      const Eigen::MatrixXd g = dN * (X.transpose() * dN).inverse();  // dN/dx
      std::vector<Eigen::Triplet<double>> entries;
      for (int a = 0; a < per; ++a) {
        const int node = mesh->cells(e, a);
        for (int d = 0; d < 3; ++d) entries.emplace_back(d, 3 * node + d, N[a]);
        // theta = curl(u) / 2
        entries.emplace_back(3, 3 * node + 2, 0.5 * g(a, 1));
        entries.emplace_back(3, 3 * node + 1, -0.5 * g(a, 2));
        entries.emplace_back(4, 3 * node + 0, 0.5 * g(a, 2));
        entries.emplace_back(4, 3 * node + 2, -0.5 * g(a, 0));
        entries.emplace_back(5, 3 * node + 1, 0.5 * g(a, 0));
        entries.emplace_back(5, 3 * node + 0, -0.5 * g(a, 1));
      }
      SparseMatrix S(6, mesh->nodes.rows() * 3);
      S.setFromTriplets(entries.begin(), entries.end());
      return SparseMatrix(S * T);
    }
    return std::nullopt;
  };
}

SolidMesh MeshSolidPart(const PartSpec& part) {
  MeshRequest request;
  request.shape = part.solid.shape;
  request.size = part.solid.size;
  request.radius = part.solid.radius;
  request.inner_radius = part.solid.inner_radius;
  request.length = part.solid.length;
  request.max_elements = part.solid.max_elements;
  request.file = part.solid.file;
  request.element_size = part.solid.element_size;
  request.order = part.solid.order;
  request.hexahedra = part.solid.hexahedra;
  request.where = part.solid.where;
  SolidMesh mesh = request.file.empty() || IsGmshFile(request.file) ? MeshWithGmsh(request)
                                                                    : ImportWithMeshio(request.file, part.solid.where);
  if (mesh.nodes.rows() > 0) {
    const Eigen::Vector3d lo = mesh.nodes.colwise().minCoeff(), hi = mesh.nodes.colwise().maxCoeff();
    CheckPartSize(part, (hi - lo).norm(),
                  part.solid.where + " (" + (request.file.empty() ? Name(part.solid.shape) : request.file) + ")");
  }
  return mesh;
}

namespace {

// RBE3 (distributing): the interface motion is the least-squares rigid fit of its node set,
//   u_k = u_c + theta x (x_k - c),  u_c = mean(u_i),  theta = A^-1 sum r_i x u_i,
//   A = sum (|r_i|^2 1 - r_i r_i^T), r_i = x_i - c,
// i.e. q_k = W u_set. The set's DOFs stay free DOFs of the model and q_k = W u is a constraint
// that the Craig-Bampton reduction imposes through multipliers (no stiffness added, no dense
// coupling of the set).
struct Rbe3 {
  std::vector<int> dofs;  // set DOFs (mesh numbering)
  Eigen::MatrixXd W;      // 6 x dofs
};

// Every RBE2 and RBE3 node set can carry the interface's rotation (CheckedPolarMoment), checked in
// interface order before either coupling is built (Rbe3Weights checks its set again: imported
// parts call it too).
void CheckCouplingSets(const PartSpec& part, const SolidMesh& mesh, const std::vector<std::vector<int>>& sets) {
  for (size_t k = 0; k < part.interfaces.size(); ++k) {
    const InterfaceSpec& i = part.interfaces[k];
    if (i.coupling == Coupling::kRbe2 || i.coupling == Coupling::kRbe3) {
      CheckedPolarMoment(mesh.nodes, sets[k], i.coupling == Coupling::kRbe2 ? "RBE2" : "RBE3", i.where, i.name);
    }
  }
}

std::vector<Rbe3> Rbe3Couplings(const PartSpec& part, const SolidMesh& mesh, const std::vector<std::vector<int>>& sets,
                                const FeModel& model) {
  std::vector<Rbe3> rbe3(part.interfaces.size());
  for (size_t k = 0; k < part.interfaces.size(); ++k) {
    if (part.interfaces[k].coupling != Coupling::kRbe3) continue;
    const std::vector<int>& set = sets[k];
    Rbe3& r3 = rbe3[k];
    r3.W =
        Rbe3Weights(mesh.nodes, set, model.interface_positions[k], part.interfaces[k].where, part.interfaces[k].name);
    for (int node : set)
      for (int i = 0; i < 3; ++i) r3.dofs.push_back(3 * node + i);
  }
  return rbe3;
}

// Model coordinates: every mesh DOF not in an RBE2 set, node by node in the mesh nodes' `order`
// (kept: its model DOF, -1 in a set), then 6 per RBE2 interface (rbe2_base: its first, -1 if not
// RBE2). The map T (mesh DOFs -> model DOFs): a node in an RBE2 set moves with the interface's
// rigid motion.
SparseMatrix RigidCouplingMap(const PartSpec& part, const SolidMesh& mesh, const std::vector<int>& owner,
                              const std::vector<int>& order, const FeModel& model, std::vector<int>& kept,
                              std::vector<int>& rbe2_base) {
  const int n_nodes = int(mesh.nodes.rows());
  std::vector<int> coupled;
  for (int s = 0; s < n_nodes; ++s) {
    if (owner[s] >= 0) coupled.push_back(s);
  }
  CheckRegionsHeldByInterfaces(mesh.cells, mesh.nodes, coupled, part.solid.where);
  kept.assign(size_t(3 * n_nodes), -1);
  int n_kept = 0;
  for (const int s : order) {
    const bool rbe2 = owner[s] >= 0 && part.interfaces[owner[s]].coupling == Coupling::kRbe2;
    for (int d = 0; d < 3; ++d) {
      if (!rbe2) kept[3 * s + d] = n_kept++;
    }
  }
  rbe2_base.assign(part.interfaces.size(), -1);
  int n_model = n_kept;
  for (size_t k = 0; k < part.interfaces.size(); ++k) {
    if (part.interfaces[k].coupling == Coupling::kRbe2) {
      rbe2_base[k] = n_model;
      n_model += 6;
    }
  }
  std::vector<Eigen::Triplet<double>> t_entries;
  for (int s = 0; s < n_nodes; ++s) {
    if (owner[s] >= 0 && part.interfaces[owner[s]].coupling == Coupling::kRbe2) {
      const int base = rbe2_base[owner[s]];
      const Eigen::Matrix3d arm =
          -Skew<double>(Eigen::Vector3d(mesh.nodes.row(s).transpose() - model.interface_positions[owner[s]]));
      for (int d = 0; d < 3; ++d) {
        t_entries.emplace_back(3 * s + d, base + d, 1.0);
        for (int c = 0; c < 3; ++c) {
          if (arm(d, c) != 0.0) t_entries.emplace_back(3 * s + d, base + 3 + c, arm(d, c));
        }
      }
      continue;
    }
    for (int d = 0; d < 3; ++d) t_entries.emplace_back(3 * s + d, kept[3 * s + d], 1.0);
  }
  SparseMatrix T(3 * n_nodes, n_model);
  T.setFromTriplets(t_entries.begin(), t_entries.end());
  return T;
}

// The assembly's map of mesh nodes to model nodes: a free node (3 DOFs) each, in the `order` of
// RigidCouplingMap, then one node (6 DOFs) per RBE2 interface, on which its set's nodes hang by
// their arms.
SolidDofMap AssemblyMap(const PartSpec& part, const SolidMesh& mesh, const std::vector<int>& owner,
                        const std::vector<int>& order, const FeModel& model, const std::vector<int>& kept,
                        const std::vector<int>& rbe2_base, int n_model) {
  const int n_nodes = int(mesh.nodes.rows());
  SolidDofMap map;
  map.n_dofs = n_model;
  map.model_node.assign(n_nodes, -1);
  map.arm.assign(n_nodes, Eigen::Matrix3d::Zero());
  std::vector<int> interface_node(part.interfaces.size(), -1);
  for (const int s : order) {
    if (kept[3 * s] < 0) continue;
    map.model_node[s] = int(map.first_dof.size());
    map.first_dof.push_back(kept[3 * s]);
    map.dofs.push_back(3);
  }
  for (size_t k = 0; k < part.interfaces.size(); ++k) {
    if (rbe2_base[k] < 0) continue;
    interface_node[k] = int(map.first_dof.size());
    map.first_dof.push_back(rbe2_base[k]);
    map.dofs.push_back(6);
  }
  for (int s = 0; s < n_nodes; ++s) {
    if (kept[3 * s] >= 0) continue;
    map.model_node[s] = interface_node[owner[s]];
    map.arm[s] = -Skew<double>(Eigen::Vector3d(mesh.nodes.row(s).transpose() - model.interface_positions[owner[s]]));
  }
  return map;
}

// The interfaces' couplings: an RBE2 interface's six model DOFs; an RBE3 interface's weights.
void InterfaceCouplings(const PartSpec& part, const std::vector<Rbe3>& rbe3, const std::vector<int>& kept,
                        const std::vector<int>& rbe2_base, int n_model, FeModel& model) {
  for (size_t k = 0; k < part.interfaces.size(); ++k) {
    std::vector<FullDof> dofs;
    SparseMatrix W(0, n_model);
    if (rbe2_base[k] >= 0) {
      for (int d = 0; d < 6; ++d) dofs.push_back({rbe2_base[k] + d});
    } else {
      std::vector<Eigen::Triplet<double>> w;
      for (size_t a = 0; a < rbe3[k].dofs.size(); ++a)
        for (int i = 0; i < 6; ++i) w.emplace_back(i, kept[rbe3[k].dofs[a]], rbe3[k].W(i, long(a)));
      W.resize(6, n_model);
      W.setFromTriplets(w.begin(), w.end());
    }
    model.interface_dofs.push_back(dofs);
    model.interface_weights.push_back(W);
  }
}

// The mesh nodes in the order of the model's DOFs: as meshed, or part by part of a partition
// (in mesh order within a part).
std::vector<int> NodeOrder(int n_nodes, const NodePartition* partition) {
  std::vector<int> order(static_cast<size_t>(n_nodes));
  std::iota(order.begin(), order.end(), 0);
  if (partition) {
    std::stable_sort(order.begin(), order.end(),
                     [&](int a, int b) { return partition->part[size_t(a)] < partition->part[size_t(b)]; });
  }
  return order;
}

// This rank's columns of a model numbered part by part: its part's DOFs (the RBE2 interfaces',
// numbered last, with the last part's). PETSc's even split instead where a part would hold none.
ColumnShare ShareOfPart(const NodePartition& partition, const std::vector<int>& kept, long n_model) {
  std::vector<long> first(size_t(partition.parts) + 1, 0);
  for (size_t s = 0; s < partition.part.size(); ++s)
    if (kept[3 * s] >= 0) first[size_t(partition.part[s]) + 1] += 3;
  for (int p = 0; p < partition.parts; ++p) first[size_t(p) + 1] += first[size_t(p)];
  first.back() = n_model;
  for (int p = 0; p < partition.parts; ++p)
    if (first[size_t(p) + 1] == first[size_t(p)]) return ShareOfColumns(n_model);
  const int rank = DistributedRank();
  return {first[size_t(rank)], first[size_t(rank) + 1] - first[size_t(rank)]};
}

}  // namespace

FeModel BuildSolidModel(const PartSpec& part, const ProgressFn& progress) {
  Stopwatch clock;
  auto mesh = std::make_shared<SolidMesh>(MeshSolidPart(part));
  if (progress) progress("mesh", clock.Seconds(), MeshSummary(part, *mesh));
  return BuildSolidModelOn(part, mesh, false, nullptr, progress);
}

std::string MeshSummary(const PartSpec& part, const SolidMesh& mesh) {
  return std::to_string(mesh.nodes.rows()) + " nodes, " + std::to_string(mesh.cells.rows()) + " " +
         SolidTypeName(mesh.type) + " elements" + (part.solid.file.empty() ? "" : " from " + part.solid.file);
}

FeModel BuildSolidModelOn(const PartSpec& part, const std::shared_ptr<const SolidMesh>& mesh, bool shared,
                          const NodePartition* partition, const ProgressFn& progress) {
  // Interface node sets: a named set of the mesh, or nodes picked by geometry.
  Stopwatch clock;
  FeModel model;
  const InterfaceNodes interface_nodes =
      ResolveInterfaceNodes(part, mesh->nodes, mesh->node_sets, mesh.get(), "the mesh");
  for (size_t k = 0; k < part.interfaces.size(); ++k) {
    model.interface_names.push_back(part.interfaces[k].name);
    model.interface_positions.push_back(interface_nodes.positions[k]);
  }
  model.interface_node_sets = interface_nodes.sets;
  CheckCouplingSets(part, *mesh, interface_nodes.sets);
  const std::vector<Rbe3> rbe3 = Rbe3Couplings(part, *mesh, interface_nodes.sets, model);
  std::vector<int> kept, rbe2_base;
  const std::vector<int> order = NodeOrder(int(mesh->nodes.rows()), partition);
  const SparseMatrix T = RigidCouplingMap(part, *mesh, interface_nodes.owner, order, model, kept, rbe2_base);
  const int n_model = int(T.cols());
  if (progress) {
    progress("couplings", clock.Seconds(),
             std::to_string(part.interfaces.size()) + " interfaces (" + interface_nodes.summary + "), " +
                 std::to_string(n_model) + " model DOFs");
  }

  // Element matrices straight onto the model DOFs (RBE2 folded in per element).
  clock.Restart();
  const SolidDofMap map = AssemblyMap(part, *mesh, interface_nodes.owner, order, model, kept, rbe2_base, n_model);
  if (shared) model.columns = partition ? ShareOfPart(*partition, kept, n_model) : ShareOfColumns(n_model);
  if (shared && partition) {
    for (size_t c = 0; c < partition->cell_part.size(); ++c)
      if (partition->cell_part[c] == DistributedRank()) model.rank_cells.push_back(int(c));
  }
  const long assembled = AssembleSolid(*mesh, part.material, map, &model.K, &model.M, model.columns);
  if (progress) {
    const std::string entries = std::to_string(model.K.nonZeros()) + " stiffness entries";
    const std::string cells = std::to_string(mesh->cells.rows());
    progress("assembly", clock.Seconds(),
             model.columns.whole() ? cells + " elements, " + entries
                                   : std::to_string(assembled) + " of " + cells + " elements, " + entries + " in the " +
                                         std::to_string(model.columns.count) + " of " + std::to_string(n_model) +
                                         " columns rank " + std::to_string(DistributedRank()) + " holds");
  }
  InterfaceCouplings(part, rbe3, kept, rbe2_base, n_model, model);
  model.mesh_map = T;
  model.dofs_per_node = 3;
  model.nodes = mesh->nodes;
  model.cells = mesh->cells;
  model.cell_type = CellOf(mesh->type);
  model.element_type = SolidTypeName(mesh->type);

  // Material point interpolation: displacement and small rotation (curl / 2) at x.
  model.interpolate_at = SolidInterpolation(mesh, T);
  return model;
}

}  // namespace femb
