#include "solver/analysis/modal_analysis.h"

#include <Eigen/Eigenvalues>
#include <cmath>

namespace femb {

ModalResult LinearizedModes(const SystemModel& model, SystemState& state, double load_time, int count) {
  ModalResult result;
  const DofMap dofs(model);
  const SystemForces forces = AssembleStatic(model, dofs, state, load_time, true);
  if (!forces.ok) {
    result.message = forces.message;
    return result;
  }
  const int n = dofs.n_dofs();
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n, n);
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    const BodyConfiguration c = BodyConfigurationOf(model, state, int(b));
    Eigen::MatrixXd Mb;
    const Eigen::VectorXd w = Eigen::VectorXd::Zero(model.bodies[b].n_coordinates());
    model.bodies[b].InertiaForce(c, state.frames[b], w, w, nullptr, &Mb, nullptr);
    const std::vector<int> map = BodyDofMap(model, dofs, int(b));
    for (size_t i = 0; i < map.size(); ++i) {
      for (size_t j = 0; j < map.size(); ++j) {
        if (map[i] >= 0 && map[j] >= 0) M(map[i], map[j]) += Mb(i, j);
      }
    }
  }
  // The tangent on SO(3) with spatial increments is symmetric at equilibrium up to the load
  // terms; the symmetric part defines the conservative linearization.
  const Eigen::MatrixXd K = 0.5 * (forces.tangent + forces.tangent.transpose());
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(K, 0.5 * (M + M.transpose()));
  if (eig.info() != Eigen::Success) {
    result.message = "generalized eigen solver failed (is every unknown carrying mass?)";
    return result;
  }
  const int m = count > 0 ? std::min(count, n) : n;
  result.frequencies_hz.resize(m);
  for (int k = 0; k < m; ++k) {
    const double l = eig.eigenvalues()[k];
    result.frequencies_hz[k] = std::copysign(std::sqrt(std::abs(l)), l) / (2 * M_PI);
  }
  result.shapes = eig.eigenvectors().leftCols(m);
  result.ok = true;
  return result;
}

}  // namespace femb
