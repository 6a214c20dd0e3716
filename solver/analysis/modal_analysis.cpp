#include "solver/analysis/modal_analysis.h"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <cmath>

namespace femb {

ModalResult LinearizedModes(const SystemModel& model, SystemState& state, double load_time, int count) {
  ModalResult result;
  const DofMap& dofs = model.dofs();
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
    BodyData data = Evaluate(model.bodies[b], c, state.frames[b]);
    InertiaForce(model.bodies[b], data, w, w, nullptr, &Mb, nullptr);
    ScatterBody(BodyMap(model, dofs, state, int(b)), nullptr, &Mb, nullptr, &M_entries);
  }
  // The tangent on SO(3) with spatial increments is symmetric at equilibrium up to the load
  // terms; the symmetric part defines the conservative linearization.
  const Eigen::MatrixXd M(ToMatrix(n, M_entries));
  const Eigen::MatrixXd tangent(forces.tangent);
  // Prescribed coordinates are held at their values: modes of the others.
  std::vector<int> free;
  for (int j : dofs.solved())
    if (!dofs.multiplier(j)) free.push_back(j);
  Eigen::MatrixXd K(free.size(), free.size()), Mf(free.size(), free.size());
  for (size_t i = 0; i < free.size(); ++i) {
    for (size_t j = 0; j < free.size(); ++j) {
      K(i, j) = 0.5 * (tangent(free[i], free[j]) + tangent(free[j], free[i]));
      Mf(i, j) = 0.5 * (M(free[i], free[j]) + M(free[j], free[i]));
    }
  }
  // Closed loops: the motions that keep them closed, dq = N y with G N = 0 (N: an orthonormal
  // basis of the null space of the constraint Jacobian on the free coordinates, from the QR
  // factorization of G^T); K and M projected, N^T K N and N^T M N (K with the multipliers'
  // geometric stiffness d(G^T lambda)/dq: a preloaded loop's stiffness).
  Eigen::MatrixXd N = Eigen::MatrixXd::Identity(Eigen::Index(free.size()), Eigen::Index(free.size()));
  if (dofs.n_multipliers() > 0) {
    const int m = dofs.n_multipliers(), first = dofs.first_multiplier();
    Eigen::MatrixXd Gt(free.size(), m);
    for (size_t i = 0; i < free.size(); ++i)
      for (int c = 0; c < m; ++c) Gt(Eigen::Index(i), c) = tangent(first + c, free[i]);
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Gt);
    const int rank = int(qr.rank());
    const Eigen::MatrixXd Q = qr.householderQ();
    N = Q.rightCols(Q.cols() - rank);
    K = (N.transpose() * K * N).eval();
    Mf = (N.transpose() * Mf * N).eval();
  }
  const int n_free = int(N.cols());
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
  const Eigen::MatrixXd shapes = N * eig.eigenvectors().leftCols(m);
  for (size_t i = 0; i < free.size(); ++i) result.shapes.row(free[i]) = shapes.row(Eigen::Index(i));
  result.ok = true;
  return result;
}

}  // namespace femb
