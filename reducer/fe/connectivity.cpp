#include "reducer/fe/connectivity.h"

#include <cstdio>
#include <numeric>

#include "formats/input_error.h"

namespace femb {

void CheckRegionsHeldByInterfaces(const Eigen::MatrixXi& cells, const Eigen::MatrixXd& nodes,
                                  const std::vector<int>& interface_nodes, const std::string& where) {
  const int n = int(nodes.rows());
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  for (int e = 0; e < cells.rows(); ++e)
    for (int a = 1; a < cells.cols(); ++a) parent[find(cells(e, a))] = find(cells(e, 0));
  std::vector<char> held(n, 0), used(n, 0);
  for (int node : interface_nodes) held[find(node)] = 1;
  for (int e = 0; e < cells.rows(); ++e)
    for (int a = 0; a < cells.cols(); ++a) used[cells(e, a)] = 1;
  std::vector<int> count(n, 0);
  std::vector<Eigen::Vector3d> centre(n, Eigen::Vector3d::Zero());
  for (int i = 0; i < n; ++i) {
    if (!used[i]) continue;
    const int r = find(i);
    ++count[r];
    centre[r] += nodes.row(i).transpose();
  }
  for (int r = 0; r < n; ++r) {
    if (count[r] == 0 || held[r]) continue;
    const Eigen::Vector3d c = centre[r] / count[r];
    char buffer[300];
    std::snprintf(buffer, sizeof buffer,
                  "%s: a mesh region of %d nodes around (%.6g, %.6g, %.6g) is connected to no interface, so "
                  "nothing holds it (K_ii would be singular); add an interface on it or connect it",
                  where.c_str(), count[r], c.x(), c.y(), c.z());
    throw InputError(buffer);
  }
}

}  // namespace femb
