// Geometrically nonlinear solids: total Lagrangian, Green-Lagrange strain, St. Venant-
// Kirchhoff material on the same elements and quadrature as the linear model.
//   G = grad_X u,  F = 1 + G,  E = (G + G^T + G^T G) / 2,  S = D E (Voigt, engineering shear),
//   W = int E : S / 2 dV,  f_a = int F S grad N_a dV,
//   K_ab = int [ (grad N_a . S grad N_b) 1 + B_a^T D B_b ] dV,  B_a = d E / d u_a = sym(F^T (e_i x grad N_a)).
// The strain is quadratic in u, so the internal force is exactly cubic in u: its expansion about
// u = 0 is K0 u + f2(u, u) + f3(u, u, u), the basis of the modal derivatives (thesis 8.3) and of
// the reduced polynomial internal force. At u = 0 the tangent is the linear stiffness of
// solid_element.h.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "formats/part_file.h"
#include "reducer/fe/fe_model.h"
#include "reducer/fe/solid_element.h"

namespace femb {

struct NonlinearElementState {
  double energy = 0.0;
  Eigen::VectorXd force;    ///< 3 n
  Eigen::MatrixXd tangent;  ///< 3 n x 3 n (only when asked)
};

/// The reduced internal force of u = V q on a mesh: with the Green-Lagrange strain it is
/// exactly cubic in q (thesis 8.3). Pair index p = (j, k), j <= k, in the order (0,0), (0,1), ...,
/// (0,n-1), (1,1), ...; z_p(q) = m_p q_j q_k with m_p = 1 (j = k) or 2 (j < k). At a quadrature
/// point the Voigt strain is E = L q + Q z / 2 with L_j = E_lin(v_j), Q_p = Voigt of
/// (G_j^T G_k + G_k^T G_j) / 2. The strain energy is then
///   W(q) = q^T K q / 2 + q^T A z + z^T B z,  K = int L^T D L,  A = int L^T D Q / 2,
///   B = int Q^T D Q / 8   (n x n, n x P, P x P; P = n (n + 1) / 2),
/// and f(q) = dW/dq, K_t(q) = d2W/dq2 (reduced_polynomial.h evaluates them).
struct ReducedPolynomial {
  Eigen::MatrixXd K, A, B;  ///< B is 0 x 0 when the cubic part was not asked for
  /// With stress fields u_f (PolynomialRequest): S(f, p) = int sigma(u_f) . Q_p dV, the reduced
  /// geometric stiffness of the stress sigma(u_f) = D E_lin(u_f): K_sigma,f = Phi^T G(sigma_f) Phi
  /// has entries (j, k) and (k, j) equal to S(f, p(j, k)) (sigma . Q_p = sigma : G_j^T G_k).
  Eigen::MatrixXd S;
};

/// What to accumulate besides K and A: the cubic part B (P x P: the costly one, P = n (n + 1) / 2)
/// and the geometric stiffness of given displacement fields' stresses (ReducedPolynomial::S).
struct PolynomialRequest {
  bool cubic = true;
  const Eigen::MatrixXd* stress_fields = nullptr;  ///< n_dofs x n_fields on the model's DOF vector
  /// The first `static_coordinates` basis vectors are the interfaces' static modes; the
  /// completion fields (`pair_fields`) are made K-orthogonal to the others (internal modes, modal
  /// derivatives: CompletionProjection), so that their stress does no work on them. -1: kept as
  /// given.
  int static_coordinates = -1;
};

/// One element: `X` n x 3 node coordinates, `u` its 3 n displacements (node-major).
NonlinearElementState SvkSolidElement(SolidType type, const Eigen::MatrixXd& X, const MaterialSpec& material,
                                      const Eigen::VectorXd& u, bool with_tangent);

/// A geometrically nonlinear model on some DOF vector: strain energy, its gradient (the internal
/// force) and Hessian (the tangent, symmetric, both triangles stored).
class NonlinearModel {
 public:
  virtual ~NonlinearModel() = default;
  virtual long n_dofs() const = 0;
  virtual double Energy(const Eigen::VectorXd& u) const = 0;
  virtual Eigen::VectorXd Force(const Eigen::VectorXd& u) const = 0;
  virtual SparseMatrix Tangent(const Eigen::VectorXd& u) const = 0;
};

/// Accumulates the reduced polynomial (ReducedPolynomial) over quadrature points: at each, the
/// weight dV, a factor C of the 6 x 6 stiffness D = C^T C (Cholesky, or the square root of a
/// diagonal D, zeros allowed), the linear strain rows L (6 x n) and the quadratic ones Q (6 x P).
/// `L_fields` (6 x n_fields): the linear strains of the stress fields at the point; `Q_fields`
/// (default Q): the quadratic strains their geometric stiffness uses (without the interface
/// rotation completion: SuperelementBody's exact inertia does not see that second-order field,
/// and the inertia load's stress does work on it that nothing balances; on a rotating cantilever
/// the completion added rho A Omega^2 L^2 / 12 to the tip slope's geometric stiffness).
class PolynomialAccumulator {
 public:
  PolynomialAccumulator(int n, bool cubic = true, int n_fields = 0);
  void Add(double dV, const Eigen::Matrix<double, 6, 6>& C, const Eigen::MatrixXd& L, const Eigen::MatrixXd& Q,
           const Eigen::MatrixXd* L_fields = nullptr, const Eigen::MatrixXd* Q_fields = nullptr);
  ReducedPolynomial Finish();

 private:
  void Flush();
  static constexpr int kPointsPerBlock = 64;
  bool cubic_;
  ReducedPolynomial r_;
  Eigen::MatrixXd stack_;
  int stacked_ = 0;
};

/// A whole mesh (3 DOFs per mesh node, node-major), quadrature data computed once.
/// The Green-Lagrange model of a solid mesh (3 DOFs per node). On the MPI ranks of a distributed
/// reduction each rank takes a share of the elements (`held`: a range of the cells; all by
/// default) and the results are summed over the ranks (shared_columns.h), whole on every rank:
/// every rank must then make the same calls. The tangent is for one process only. On a rank's own
/// cells (RankMesh, solid_ranks.h: `nodes` and `cells` its compact numbering, `held` all of them)
/// the reduced polynomial is summed the same way; the force, a vector of the rank's own nodes,
/// is not.
class SvkSolidMesh : public NonlinearModel {
 public:
  SvkSolidMesh(SolidType type, const Eigen::MatrixXd& nodes, const Eigen::MatrixXi& cells, const MaterialSpec& material,
               const ColumnShare& held = ColumnShare());
  long n_dofs() const override { return 3 * n_nodes_; }
  double Energy(const Eigen::VectorXd& u) const override;
  Eigen::VectorXd Force(const Eigen::VectorXd& u) const override;
  /// The force of the cells held only, not summed over the ranks (on a rank's own cells: a vector
  /// of its nodes). Force on one process.
  Eigen::VectorXd OwnForce(const Eigen::VectorXd& u) const;
  SparseMatrix Tangent(const Eigen::VectorXd& u) const override;
  friend Eigen::MatrixXd CompletionProjection(const SvkSolidMesh& solid, const Eigen::MatrixXd& mesh_shapes,
                                              const Eigen::MatrixXd& fields, int first);
  friend ReducedPolynomial ReduceSvk(const SvkSolidMesh& solid, const Eigen::MatrixXd& mesh_shapes,
                                     const std::vector<std::pair<int, Eigen::VectorXd>>& pair_fields,
                                     const PolynomialRequest& request);

 private:
  // Per quadrature point: dN/dX (n x 3) and the volume weight; per element, its points.
  template <class Visit>
  void ForEachPoint(const Eigen::VectorXd& u, Visit visit) const;
  int n_per_cell_;
  long n_nodes_;
  Eigen::MatrixXi cells_;
  ColumnShare held_;  ///< the elements held (of the cells' rows)
  long first_cell() const { return held_.first; }
  long end_cell() const { return held_.end(cells_.rows()); }
  Eigen::Matrix<double, 6, 6> D_;
  int points_per_cell_;
  std::vector<Eigen::MatrixXd> dNdX_;  ///< cell-major, points_per_cell_ per held cell
  std::vector<double> dV_;
};

/// `mesh_shapes`: the basis on the mesh DOFs (3 per node), n_mesh x n. See ReducedPolynomial.
/// `pair_fields` (p, W_p): second-order displacement fields u = V q + sum_p z_p W_p whose linear
/// strain joins the quadratic strain, Q_p += 2 E_lin(W_p) (their higher-order terms are dropped:
/// the strain stays quadratic in q). Used for the second-order rotation of interface faces.
ReducedPolynomial ReduceSvk(const SvkSolidMesh& solid, const Eigen::MatrixXd& mesh_shapes,
                            const std::vector<std::pair<int, Eigen::VectorXd>>& pair_fields = {},
                            const PolynomialRequest& request = {});

/// The completion fields' work with the basis vectors V from `first` on (internal modes, modal
/// derivatives), made zero: a = (V^T K V)^-1 V^T K W (n - first x n_fields, from the point strains
/// of the linear model), and ReduceSvk uses W' = W - V a. Those vectors vanish on the interfaces
/// and their stress is balanced by body forces (K phi = omega^2 M phi inside), which the exact
/// inertia applies to the basis' field and not to the completion's, so their work on the
/// completion's interior would be balanced by nothing: a rotating cantilever in one body whose
/// basis stretches it (an axial mode, modal derivatives) lost or doubled its centrifugal
/// stiffening (a TET10 bar with the derivatives of its modes' pairs: +12% / -16%). W' changes
/// only the parametrization: the basis spans the same fields, and the static modes' rows (K psi
/// vanishes inside) are unchanged. Under a rigid rotation of the whole part a second-order
/// V a (theta theta) is left, which the internal coordinates take up (V a is theirs).
Eigen::MatrixXd CompletionProjection(const SvkSolidMesh& solid, const Eigen::MatrixXd& mesh_shapes,
                                     const Eigen::MatrixXd& fields, int first);

/// The second-order completion of the interface rotations of a solid part (RBE2 faces): with
/// linear static modes a local rotation theta of interface k moves its face by theta x r only,
/// which the Green-Lagrange strain sees as a stretch theta^2 / 2 (at 0.09 rad on a 0.5 mm leaf
/// the polynomial body came out 38% too stiff). A finite rotation moves the face by
/// (R(theta) - 1) r = theta x r + theta~^2 r / 2 + O(theta^3). For each pair p = (a, b), a <= b,
/// of interface k's rotation coordinates (C_p = sym(e_a~ e_b~) / 2, positions from the frame
/// origin o):
///   W_p = phi_k(x) C_p (x - o) - Psi_k C_p (X_k - o),
/// phi_k the smooth weight that is 1 on face k and 0 on the others (the axial component of the
/// static mode of interface k's translation along x; the phi_k add up to 1), Psi_k the static
/// modes of interface k's translations. On face k it is C_p (x - X_k), the face's own second-order
/// rotation; and for a rigid rotation of the whole part (all theta_k equal, u_k = (R - 1) X_k)
/// the second-order field is exactly theta~^2 (x - o) / 2, strain-free. Pair indices p refer to
/// the n reduced coordinates (reduced_polynomial.h).
/// Solid meshes only (3 DOFs per node): on beam nodes W_p would vanish at every interface (their
/// nodes carry their exact positions) and add only interior work with the stress of the shapes
/// that vanish there (axial modes, modal derivatives), which the exact inertia does not balance.
/// Measured on the rotating beam example in one body (tip deflection, RMS off the 20-body
/// reference): with it 37.5% (14 internal modes, the first axial one among them) and 37.5% / 30.6%
/// / 19.3% (modal derivatives of every pair; centre of mass / mean axes / hub frame); without it
/// 1.8% for each.
std::vector<std::pair<int, Eigen::VectorXd>> InterfaceRotationCompletion(
    const Eigen::MatrixXd& mesh_nodes, const Eigen::MatrixXd& mesh_shapes,
    const std::vector<Eigen::Vector3d>& interface_points, const Eigen::Vector3d& origin);

/// Static equilibrium of a full nonlinear model by Newton with load stepping:
///   T^T f(T u) = lambda f_ext  on the free model DOFs, u = prescribed values on the others
///   (the prescribed values are scaled by lambda too), lambda = 1/steps ... 1. Converged when the
///   free residual is below tolerance x max(|lambda f_ext|, |reactions|) or the Newton correction
///   is below 1e-12 |u| (round-off in a stiff part's internal forces). `u_start`: the free DOFs'
///   first guess (continuation); zero when null.
/// `T` maps model DOFs to mesh DOFs (FeModel::mesh_map; identity when empty).
struct NonlinearStaticResult {
  std::vector<double> load_factor;
  std::vector<Eigen::VectorXd> u;         ///< model DOFs per converged step
  std::vector<Eigen::VectorXd> reaction;  ///< T^T f(T u) - lambda f_ext on all model DOFs
  std::vector<int> iterations;
  bool converged = true;
  std::string message;  ///< why it stopped, when not converged
};
NonlinearStaticResult SolveNonlinearStatic(const NonlinearModel& solid, const SparseMatrix& T,
                                           const std::vector<int>& prescribed_dofs,
                                           const Eigen::VectorXd& prescribed_values, const Eigen::VectorXd& f_ext,
                                           int steps, double tolerance = 1e-9, int max_iterations = 30,
                                           const Eigen::VectorXd* u_start = nullptr);

}  // namespace femb
