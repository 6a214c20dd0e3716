// Craig-Bampton reduction (thesis 3.1, 8.1). Boundary coordinates b are the 6N interface DOFs,
// interior i the rest. With ONE sparse Cholesky factor of K_ii:
//   static constraint modes   Psi_c = -K_ii^-1 K_ib                      (n_i x 6N)
//   fixed-interface modes     K_ii Phi_i = M_ii Phi_i Lambda, Phi_i^T M_ii Phi_i = 1 (n_i x m)
//   basis                     Phi = [1 0; Psi_c Phi_i]
//   reduced                   K_r = Phi^T K Phi = [K_bb + K_bi Psi_c, 0; 0, Lambda]
//                             M_r = Phi^T M Phi
// ordered [interface 1 (u, theta), ..., interface N, internal modes, modal derivatives].
// Modal derivatives (thesis 8.3, after Idelsohn & Cardona and Wu & Tiso): for pairs (i, j) of
// the basis vectors, theta_ij = -K_ii^-1 ((dK/dq_j) phi_i)_i with the interfaces held (8.22-8.23:
// zero at the interface DOFs, W theta = 0 at RBE3 interfaces), on the same factor; then deflated
// against the internal modes and the derivatives kept so far in the M_ii inner product (twice,
// classical Gram-Schmidt), dropped when less than `tolerance` of the M-norm remains, and
// M-normalized.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "formats/kinds.h"
#include "reducer/fe/fe_model.h"
#include "reducer/linalg/sparse_cholesky.h"
#include "reducer/progress.h"

namespace femb {

struct DerivativeRequest {
  std::vector<std::pair<int, int>> pairs;  ///< indices into the Craig-Bampton coordinates
  double tolerance = 1e-4;
  /// (dK/dq_j) phi_i on the full model DOFs, one column per pair, given the Craig-Bampton
  /// shapes (n_full x (6N + m)); on MPI ranks sharing the model by columns this rank's rows of
  /// both (those of model.columns).
  std::function<Eigen::MatrixXd(const Eigen::MatrixXd& shapes, const std::vector<std::pair<int, int>>& pairs)>
      stiffness_derivative;
};

struct CraigBamptonResult {
  bool ok = false;
  std::string message;     ///< why it failed (numerical), when !ok
  Eigen::MatrixXd K, M;    ///< reduced, n_r x n_r
  Eigen::VectorXd lambda;  ///< internal eigenvalues omega^2, ascending
  /// The eigenvalue after the last internal mode kept, solved for to tell whether the cut splits
  /// a group of equal frequencies (a round or square section, a symmetric part); 0 when none is
  /// left to solve for.
  double next_lambda = 0.0;
  /// n_full x n_r: full DOF field of each reduced coordinate; on MPI ranks sharing the model by
  /// columns this rank's rows of it, those of model.columns (GatherRows makes the whole).
  Eigen::MatrixXd shapes;
  FactorizationInfo factorization;
  long eigen_linear_solves = 0;
  bool dense_eigen = false;
  std::vector<std::pair<int, int>> derivative_pairs;  ///< of the derivatives kept, in order
  /// With `inertia_fields`: the static response to each field's inertia load with the
  /// interfaces held, u_k = -K_ii^-1 (M A_k)_i (zero on the interface DOFs, W u = 0 at RBE3
  /// interfaces), minus the part the internal modes and modal derivatives V carry statically
  /// (K_ii-orthogonal projection, V (V^T K_ii V)^-1 V^T f: that part is the basis's own
  /// response), n_full x k (on MPI ranks this rank's rows, as `shapes`).
  Eigen::MatrixXd inertia_displacements;
};

/// `internal_modes` fixed-interface modes are kept. Reports stages through `progress`. With
/// `memory_limit_bytes` > 0, refuses (factorization.too_big) when the factor of K_ii would not fit.
/// `derivatives` (optional) appends modal derivatives to the basis. `inertia_fields` (optional,
/// n x k on one process; on MPI ranks sharing K and M this rank's rows of them, HeldRows of the
/// model's columns) asks for the inertia displacements. `solver`: the interior's factor and eigen
/// solver (linalg/interior_solver.h).
CraigBamptonResult CraigBamptonReduce(const FeModel& model, int internal_modes, const ProgressFn& progress,
                                      long dense_limit = 200, double memory_limit_bytes = 0,
                                      const DerivativeRequest* derivatives = nullptr,
                                      const Eigen::MatrixXd* inertia_fields = nullptr,
                                      ReductionSolver solver = ReductionSolver::kCholmod);
/// The same, holding the model's K and M only as the blocks of the interior and interface DOFs
/// while the interior's factor lives (released from `model` and rebuilt from the blocks, the same
/// entries, before the projection, also when the reduction fails): the peak memory is lower by
/// the size of K and M.
CraigBamptonResult CraigBamptonReduce(FeModel& model, int internal_modes, const ProgressFn& progress,
                                      long dense_limit = 200, double memory_limit_bytes = 0,
                                      const DerivativeRequest* derivatives = nullptr,
                                      const Eigen::MatrixXd* inertia_fields = nullptr,
                                      ReductionSolver solver = ReductionSolver::kCholmod);

/// The six rigid-body motions (translations, rotations about the part origin) as fields on the
/// model DOFs, n_dofs x 6.
Eigen::MatrixXd RigidFields(const FeModel& model);

/// The 12 unit inertia acceleration fields (formats/superelement.h kInertiaLoadCases) at a point
/// x measured from the origin they refer to: e_i, e_i x x, (e_i e_i^T - 1) x, (e_i e_j^T + e_j e_i^T) x.
Eigen::Matrix<double, 3, 12> InertiaFieldAt(const Eigen::Vector3d& x);

/// The 12 fields on the model DOFs about the part origin (beams: the rotation DOFs follow the
/// angular accelerations), n_dofs x 12.
Eigen::MatrixXd InertiaFields(const FeModel& model);

/// The inertia invariants of a basis (formats/superelement.h: inertia_gamma, inertia_xi), from
/// `shapes` held as CraigBamptonResult::shapes (on MPI ranks this rank's rows of them):
/// Gamma_a = Phi^T M S_a Phi and Xi_ab = (S_a Phi)^T M (S_b Phi), S_a the skew matrix of e_a on
/// every DOF triple (beams: u and theta of each node; solids: each mesh node's u, and u and theta
/// of each RBE2 interface node, whose turned field is then the rigid face's nearest: the face
/// rotates with its centre).
void InertiaInvariants(const FeModel& model, const Eigen::MatrixXd& shapes, std::vector<Eigen::MatrixXd>* gamma,
                       std::vector<Eigen::MatrixXd>* xi);

/// The interior DOFs (all DOFs not used by an interface), ascending.
std::vector<int> InteriorDofs(const FeModel& model);

}  // namespace femb
