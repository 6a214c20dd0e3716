#include "reducer/fe/solid_model.h"

#include <Eigen/Dense>
#include <memory>

#include "formats/input_error.h"
#include "reducer/fe/solid_element.h"
#include "reducer/mesh/gmsh_mesher.h"

namespace femb {
namespace {

Eigen::Matrix3d SkewOf(const Eigen::Vector3d& a) {
  Eigen::Matrix3d m;
  m << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return m;
}

// Reference coordinates of x in element e, or false when outside (tolerance tol).
bool Locate(const SolidMesh& mesh, int e, const Eigen::Vector3d& x, Eigen::Vector3d* xi) {
  const int n = SolidNodeCount(mesh.type);
  Eigen::MatrixXd X(n, 3);
  for (int a = 0; a < n; ++a) X.row(a) = mesh.nodes.row(mesh.cells(e, a));
  const bool tet = mesh.type == SolidType::kTet4 || mesh.type == SolidType::kTet10;
  Eigen::Vector3d p = tet ? Eigen::Vector3d(0.25, 0.25, 0.25) : Eigen::Vector3d::Zero();
  Eigen::VectorXd N;
  Eigen::MatrixXd dN;
  for (int it = 0; it < 20; ++it) {
    SolidShapeFunctions(mesh.type, p, &N, &dN);
    const Eigen::Vector3d r = X.transpose() * N - x;
    const Eigen::Matrix3d J = X.transpose() * dN;
    if (std::abs(J.determinant()) < 1e-300) return false;
    const Eigen::Vector3d d = J.lu().solve(r);
    p -= d;
    if (d.norm() < 1e-12) break;
  }
  const double tol = 1e-9;
  const bool inside = tet ? (p.minCoeff() >= -tol && p.sum() <= 1 + tol)
                          : (p.cwiseAbs().maxCoeff() <= 1 + tol);
  *xi = p;
  return inside;
}

}  // namespace

FeModel BuildSolidModel(const PartSpec& part) {
  MeshRequest request;
  request.shape = part.solid.shape;
  request.size = part.solid.size;
  request.file = part.solid.file;
  request.element_size = part.solid.element_size;
  request.order = part.solid.order;
  request.where = part.solid.where;
  auto mesh = std::make_shared<SolidMesh>(MeshWithGmsh(request));
  const int n_nodes = int(mesh->nodes.rows()), per = SolidNodeCount(mesh->type);

  // Element matrices on the mesh DOFs.
  std::vector<Eigen::Triplet<double>> k_entries, m_entries;
  Eigen::MatrixXd X(per, 3);
  for (int e = 0; e < mesh->cells.rows(); ++e) {
    for (int a = 0; a < per; ++a) X.row(a) = mesh->nodes.row(mesh->cells(e, a));
    const SolidElementMatrices em = ComputeSolidElement(mesh->type, X, part.material, e);
    for (int a = 0; a < per; ++a)
      for (int b = 0; b < per; ++b)
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) {
            const int r = 3 * mesh->cells(e, a) + i, c = 3 * mesh->cells(e, b) + j;
            k_entries.emplace_back(r, c, em.K(3 * a + i, 3 * b + j));
            if (i == j) m_entries.emplace_back(r, c, em.M(3 * a + i, 3 * b + j));
          }
  }
  SparseMatrix K_mesh(3 * n_nodes, 3 * n_nodes), M_mesh(3 * n_nodes, 3 * n_nodes);
  K_mesh.setFromTriplets(k_entries.begin(), k_entries.end());
  M_mesh.setFromTriplets(m_entries.begin(), m_entries.end());

  // Interface couplings (RBE2).
  std::vector<int> owner(n_nodes, -1);
  FeModel model;
  for (size_t k = 0; k < part.interfaces.size(); ++k) {
    const InterfaceSpec& i = part.interfaces[k];
    auto set = mesh->node_sets.find(i.group);
    if (set == mesh->node_sets.end()) {
      std::string known;
      for (const auto& [name, _] : mesh->node_sets) known += (known.empty() ? "" : ", ") + name;
      throw InputError(i.where + ": interface '" + i.name + "': node set '" + i.group + "' not found in the mesh (known: " +
                       (known.empty() ? "none" : known) + ")");
    }
    if (set->second.empty()) throw InputError(i.where + ": interface '" + i.name + "': node set '" + i.group + "' is empty");
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (int node : set->second) {
      if (owner[node] >= 0) {
        throw InputError(i.where + ": interface '" + i.name + "': node set '" + i.group + "' shares nodes with interface '" +
                         part.interfaces[owner[node]].name + "' (rigid couplings must not overlap)");
      }
      owner[node] = int(k);
      centroid += mesh->nodes.row(node).transpose();
    }
    centroid /= double(set->second.size());
    model.interface_names.push_back(i.name);
    model.interface_positions.push_back(i.location ? *i.location : centroid);
  }
  std::vector<int> kept(n_nodes, -1);
  int n_kept = 0;
  for (int s = 0; s < n_nodes; ++s) {
    if (owner[s] < 0) {
      kept[s] = n_kept;
      n_kept += 3;
    }
  }
  const int n_model = n_kept + 6 * int(part.interfaces.size());
  std::vector<Eigen::Triplet<double>> t_entries;
  for (int s = 0; s < n_nodes; ++s) {
    if (owner[s] < 0) {
      for (int d = 0; d < 3; ++d) t_entries.emplace_back(3 * s + d, kept[s] + d, 1.0);
      continue;
    }
    const int base = n_kept + 6 * owner[s];
    const Eigen::Matrix3d arm = -SkewOf(mesh->nodes.row(s).transpose() - model.interface_positions[owner[s]]);
    for (int d = 0; d < 3; ++d) {
      t_entries.emplace_back(3 * s + d, base + d, 1.0);
      for (int c = 0; c < 3; ++c) {
        if (arm(d, c) != 0.0) t_entries.emplace_back(3 * s + d, base + 3 + c, arm(d, c));
      }
    }
  }
  SparseMatrix T(3 * n_nodes, n_model);
  T.setFromTriplets(t_entries.begin(), t_entries.end());
  model.K = SparseMatrix(T.transpose() * K_mesh * T);
  model.M = SparseMatrix(T.transpose() * M_mesh * T);
  model.K = 0.5 * (model.K + SparseMatrix(model.K.transpose()));
  model.M = 0.5 * (model.M + SparseMatrix(model.M.transpose()));
  for (size_t k = 0; k < part.interfaces.size(); ++k) {
    std::vector<FullDof> dofs;
    for (int d = 0; d < 6; ++d) dofs.push_back({n_kept + 6 * int(k) + d});
    model.interface_dofs.push_back(dofs);
  }
  model.mesh_map = T;
  model.dofs_per_node = 3;
  model.nodes = mesh->nodes;
  model.cells = mesh->cells;
  model.cell_type = SolidTypeName(mesh->type);
  model.element_type = SolidTypeName(mesh->type);

  // Material point interpolation: displacement and small rotation (curl / 2) at x.
  model.interpolate_at = [mesh, T](const Eigen::Vector3d& x) -> std::optional<SparseMatrix> {
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
  return model;
}

}  // namespace femb
