#include "solver/analysis/singularity.h"

#include <Eigen/Dense>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>

namespace femb {
namespace {

constexpr int kMaxDense = 3000;

// "x", "-y" for a direction along an axis (within 8 degrees), else "(0.707, 0.707, 0)".
std::string Direction(const Eigen::Vector3d& v) {
  const Eigen::Vector3d u = v.normalized();
  int axis = 0;
  u.cwiseAbs().maxCoeff(&axis);
  if (std::abs(u[axis]) >= 0.99) return std::string(1, "xyz"[axis]);
  char buffer[80];
  std::snprintf(buffer, sizeof buffer, "(%.3g, %.3g, %.3g)", u.x(), u.y(), u.z());
  return buffer;
}

}  // namespace

std::string DescribeSingular(const SystemModel& model, const DofMap& dofs, const SystemState& state,
                             const SystemMatrix& S) {
  const std::vector<int>& free = dofs.solved();
  const int n = int(free.size());
  if (n == 0) return "";
  if (n > kMaxDense) {
    return "the system matrix (" + std::to_string(n) +
           " free coordinates) is singular; too large to name the free motion (look for a missing joint or support)";
  }
  Eigen::MatrixXd A = DenseFreeMatrix(dofs, S);
  Eigen::VectorXd d(n);
  for (int i = 0; i < n; ++i) d[i] = std::abs(A(i, i)) > 0 ? 1.0 / std::sqrt(std::abs(A(i, i))) : 1.0;
  A = d.asDiagonal() * A * d.asDiagonal();
  if (!A.allFinite()) return "the system matrix has entries that are not finite";
  Eigen::BDCSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullV);
  const Eigen::VectorXd& sigma = svd.singularValues();
  if (sigma[n - 1] > 1e-13 * sigma[0]) return "";
  Eigen::VectorXd null = Eigen::VectorXd::Zero(dofs.n_dofs());
  const Eigen::VectorXd v = d.asDiagonal() * svd.matrixV().col(n - 1);
  for (int i = 0; i < n; ++i) null[free[i]] = v[i];
  // Counting the free motions: the matrix is singular (a singular value below 1e-13 of the
  // largest); the other free motions of the same model come out of the SVD at round-off of the
  // loaded tangent, which a body under load puts anywhere up to ~1e-10 (a free beam's sixth
  // rigid motion measured 7e-11 with OpenBLAS): count every singular value below 1e-9, well
  // apart from physical stiffness in this unit-diagonal scaling.
  int rank_deficiency = 0;
  for (int i = 0; i < n; ++i) rank_deficiency += sigma[i] <= 1e-9 * sigma[0];

  // The model's size: rotations times it compare with translations.
  const double diagonal = BoundingDiagonal(state.x);
  const double size = diagonal > 0 ? diagonal : 1.0;
  struct Part {
    double weight;
    std::string text;
  };
  std::vector<Part> parts;
  for (int k = 0; k < model.n_nodes(); ++k) {
    const Eigen::Matrix<double, 6, 1> m = NodeMotion(state, k, null);
    const Eigen::Vector3d t = m.head<3>(), r = size * m.tail<3>();
    const double w = std::max(t.norm(), r.norm());
    if (w == 0.0) continue;
    std::string text = "node " + model.node_names[k] + ":";
    if (t.norm() >= 0.1 * w) text += " translation along " + Direction(t);
    if (r.norm() >= 0.1 * w) text += std::string(t.norm() >= 0.1 * w ? "," : "") + " rotation about " + Direction(r);
    parts.push_back({w, text});
  }
  bool modal = false;
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    for (int i = 0; i < model.bodies[b].n_modes(); ++i) {
      const double w = std::abs(null[dofs.mode_dof(int(b)) + i]);
      if (w == 0.0) continue;
      const std::string name = b < model.body_names.size() ? "'" + model.body_names[b] + "'" : std::to_string(b);
      parts.push_back({w, "body " + name + " modal coordinate " + std::to_string(i + 1)});
    }
  }
  double largest = 0.0;
  for (const Part& p : parts) largest = std::max(largest, p.weight);
  std::stable_sort(parts.begin(), parts.end(), [](const Part& a, const Part& b) { return a.weight > b.weight; });
  std::string listed;
  int count = 0;
  for (const Part& p : parts) {
    if (p.weight < 0.1 * largest || count == 4) break;
    listed += (listed.empty() ? "" : "; ") + p.text;
    modal |= p.text.rfind("body ", 0) == 0;
    ++count;
  }
  const int more =
      int(std::count_if(parts.begin(), parts.end(), [&](const Part& p) { return p.weight >= 0.1 * largest; })) - count;
  if (more > 0) listed += "; and " + std::to_string(more) + " more";
  char head[160];
  std::snprintf(head, sizeof head,
                "the system matrix is singular (%d free motion%s, smallest/largest singular value %.1e): ",
                rank_deficiency, rank_deficiency > 1 ? "s" : "", sigma[n - 1] / sigma[0]);
  const std::string cause = modal
                                ? "; a modal coordinate with neither stiffness nor mass, or a body held by nothing"
                                : "; a missing joint or support (in a static analysis every rigid motion must be held)";
  return head + listed + cause;
}

}  // namespace femb
