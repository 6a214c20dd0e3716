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
  Triplets M_entries;
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    const BodyConfiguration c = BodyConfigurationOf(model, state, int(b));
    Eigen::MatrixXd Mb;
    const Eigen::VectorXd w = Eigen::VectorXd::Zero(model.bodies[b].n_coordinates());
    model.bodies[b].InertiaForce(c, state.frames[b], w, w, nullptr, &Mb, nullptr);
    ScatterBody(BodyMap(model, dofs, state, int(b)), nullptr, &Mb, nullptr, &M_entries);
  }
  // The tangent on SO(3) with spatial increments is symmetric at equilibrium up to the load
  // terms; the symmetric part defines the conservative linearization.
  const Eigen::MatrixXd M(ToMatrix(n, M_entries));
  const Eigen::MatrixXd tangent(forces.tangent);
  // Prescribed coordinates are held at their values: modes of the others.
  const std::vector<int>& free = dofs.solved();
  Eigen::MatrixXd K(free.size(), free.size()), Mf(free.size(), free.size());
  for (size_t i = 0; i < free.size(); ++i) {
    for (size_t j = 0; j < free.size(); ++j) {
      K(i, j) = 0.5 * (tangent(free[i], free[j]) + tangent(free[j], free[i]));
      Mf(i, j) = 0.5 * (M(free[i], free[j]) + M(free[j], free[i]));
    }
  }
  const int n_free = int(free.size());
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(K, Mf);
  if (eig.info() != Eigen::Success) {
    result.message = "generalized eigen solver failed (is every unknown carrying mass?)";
    return result;
  }
  const int m = count > 0 ? std::min(count, n_free) : n_free;
  result.frequencies_hz.resize(m);
  for (int k = 0; k < m; ++k) {
    const double l = eig.eigenvalues()[k];
    result.frequencies_hz[k] = std::copysign(std::sqrt(std::abs(l)), l) / (2 * M_PI);
  }
  result.shapes = Eigen::MatrixXd::Zero(n, m);
  for (size_t i = 0; i < free.size(); ++i) result.shapes.row(free[i]) = eig.eigenvectors().row(i).head(m);
  result.ok = true;
  return result;
}

}  // namespace femb
