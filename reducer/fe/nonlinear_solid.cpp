#include "reducer/fe/nonlinear_solid.h"

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <cmath>
#include <cstdio>

#include "formats/skew.h"
#include "reducer/linalg/dense_products.h"
#include "reducer/linalg/shared_columns.h"

namespace femb {
namespace {

using Vector6 = Eigen::Matrix<double, 6, 1>;

// The linear (engineering) Voigt strain of a displacement gradient G_ij = d u_i / d X_j.
Vector6 LinearStrain(const Eigen::Matrix3d& G) {
  Vector6 e;
  e << G(0, 0), G(1, 1), G(2, 2), G(1, 2) + G(2, 1), G(0, 2) + G(2, 0), G(0, 1) + G(1, 0);
  return e;
}

// dN/dX (n x 3) and dV at every quadrature point of one element (solid_element.h); throws for
// inverted elements.
void ElementPoints(SolidType type, const Eigen::MatrixXd& X, long element_id, std::vector<Eigen::MatrixXd>* dNdX,
                   std::vector<double>* dV) {
  for (SolidPoint& p : SolidElementPoints(type, X, element_id)) {
    dNdX->push_back(std::move(p.dNdX));
    dV->push_back(p.dV);
  }
}

// One quadrature point: adds its energy, force and (optionally) tangent to the element's.
// `U` is the element's displacements as n x 3.
void AddPoint(const Eigen::MatrixXd& g, double dV, const Eigen::Matrix<double, 6, 6>& D, const Eigen::MatrixXd& U,
              NonlinearElementState* out, bool with_tangent) {
  const int n = int(g.rows());
  const Eigen::Matrix3d G = U.transpose() * g;  // G_ij = d u_i / d X_j
  const Eigen::Matrix3d F = Eigen::Matrix3d::Identity() + G;
  const Eigen::Matrix3d E = 0.5 * (G + G.transpose() + G.transpose() * G);
  Vector6 Ev;
  Ev << E(0, 0), E(1, 1), E(2, 2), 2 * E(1, 2), 2 * E(0, 2), 2 * E(0, 1);
  const Vector6 Sv = D * Ev;
  Eigen::Matrix3d S;
  S << Sv[0], Sv[5], Sv[4], Sv[5], Sv[1], Sv[3], Sv[4], Sv[3], Sv[2];
  out->energy += 0.5 * Ev.dot(Sv) * dV;
  const Eigen::Matrix3d P = F * S;                   // first Piola-Kirchhoff stress
  const Eigen::MatrixXd f = g * P.transpose() * dV;  // n x 3: f_a = P grad N_a
  for (int a = 0; a < n; ++a) out->force.segment<3>(3 * a) += f.row(a).transpose();
  if (!with_tangent) return;
  Eigen::MatrixXd B(6, 3 * n);
  for (int a = 0; a < n; ++a)
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector3d fi = F.row(i).transpose(), ga = g.row(a).transpose();
      B.col(3 * a + i) << fi[0] * ga[0], fi[1] * ga[1], fi[2] * ga[2], fi[1] * ga[2] + fi[2] * ga[1],
          fi[0] * ga[2] + fi[2] * ga[0], fi[0] * ga[1] + fi[1] * ga[0];
    }
  out->tangent.noalias() += dV * B.transpose() * D * B;
  const Eigen::MatrixXd H = dV * g * S * g.transpose();  // geometric stiffness, n x n
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b)
      for (int i = 0; i < 3; ++i) out->tangent(3 * a + i, 3 * b + i) += H(a, b);
}

Eigen::MatrixXd AsRows(const Eigen::VectorXd& u_e) {
  return Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(u_e.data(), u_e.size() / 3, 3);
}

}  // namespace

NonlinearElementState SvkSolidElement(SolidType type, const Eigen::MatrixXd& X, const MaterialSpec& material,
                                      const Eigen::VectorXd& u, bool with_tangent) {
  const int n = SolidNodeCount(type);
  std::vector<Eigen::MatrixXd> dNdX;
  std::vector<double> dV;
  ElementPoints(type, X, 0, &dNdX, &dV);
  NonlinearElementState out;
  out.force = Eigen::VectorXd::Zero(3 * n);
  if (with_tangent) out.tangent = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  const Eigen::Matrix<double, 6, 6> D = IsotropicElasticity(material.E, material.nu);
  const Eigen::MatrixXd U = AsRows(u);
  for (size_t q = 0; q < dNdX.size(); ++q) AddPoint(dNdX[q], dV[q], D, U, &out, with_tangent);
  if (with_tangent) out.tangent = 0.5 * (out.tangent + out.tangent.transpose()).eval();
  return out;
}

SvkSolidMesh::SvkSolidMesh(SolidType type, const Eigen::MatrixXd& nodes, const Eigen::MatrixXi& cells,
                           const MaterialSpec& material, const ColumnShare& held)
    : n_per_cell_(SolidNodeCount(type)),
      n_nodes_(nodes.rows()),
      cells_(cells),
      held_(held),
      D_(IsotropicElasticity(material.E, material.nu)) {
  std::vector<Eigen::Vector3d> points;
  std::vector<double> weights;
  SolidQuadrature(type, &points, &weights);
  points_per_cell_ = int(points.size());
  dNdX_.reserve(size_t(end_cell() - first_cell()) * points.size());
  dV_.reserve(dNdX_.capacity());
  Eigen::MatrixXd X(n_per_cell_, 3);
  for (long c = first_cell(); c < end_cell(); ++c) {
    for (int a = 0; a < n_per_cell_; ++a) X.row(a) = nodes.row(cells(c, a));
    ElementPoints(type, X, c + 1, &dNdX_, &dV_);
  }
}

template <class Visit>
void SvkSolidMesh::ForEachPoint(const Eigen::VectorXd& u, Visit visit) const {
  Eigen::VectorXd u_e(3 * n_per_cell_);
  for (long c = first_cell(); c < end_cell(); ++c) {
    for (int a = 0; a < n_per_cell_; ++a) u_e.segment<3>(3 * a) = u.segment<3>(3 * long(cells_(c, a)));
    const Eigen::MatrixXd U = AsRows(u_e);
    visit(c, U, size_t(c - first_cell()) * points_per_cell_);
  }
}

double SvkSolidMesh::Energy(const Eigen::VectorXd& u) const {
  double energy = 0.0;
  NonlinearElementState e;
  ForEachPoint(u, [&](long, const Eigen::MatrixXd& U, size_t first) {
    e.energy = 0.0;
    e.force = Eigen::VectorXd::Zero(3 * n_per_cell_);
    for (int q = 0; q < points_per_cell_; ++q) AddPoint(dNdX_[first + q], dV_[first + q], D_, U, &e, false);
    energy += e.energy;
  });
  Eigen::Matrix<double, 1, 1> summed(energy);
  SumOverRanks(summed, held_);
  return summed(0, 0);
}

Eigen::VectorXd SvkSolidMesh::Force(const Eigen::VectorXd& u) const {
  Eigen::VectorXd f = OwnForce(u);
  SumOverRanks(f, held_);
  return f;
}

Eigen::VectorXd SvkSolidMesh::OwnForce(const Eigen::VectorXd& u) const {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(n_dofs());
  NonlinearElementState e;
  ForEachPoint(u, [&](long c, const Eigen::MatrixXd& U, size_t first) {
    e.force = Eigen::VectorXd::Zero(3 * n_per_cell_);
    for (int q = 0; q < points_per_cell_; ++q) AddPoint(dNdX_[first + q], dV_[first + q], D_, U, &e, false);
    for (int a = 0; a < n_per_cell_; ++a) f.segment<3>(3 * long(cells_(c, a))) += e.force.segment<3>(3 * a);
  });
  return f;
}

SparseMatrix SvkSolidMesh::Tangent(const Eigen::VectorXd& u) const {
  if (!held_.whole()) throw std::logic_error("the tangent of a share of the elements");
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(size_t(cells_.rows()) * 9 * n_per_cell_ * n_per_cell_);
  NonlinearElementState e;
  ForEachPoint(u, [&](long c, const Eigen::MatrixXd& U, size_t first) {
    e.force = Eigen::VectorXd::Zero(3 * n_per_cell_);
    e.tangent = Eigen::MatrixXd::Zero(3 * n_per_cell_, 3 * n_per_cell_);
    for (int q = 0; q < points_per_cell_; ++q) AddPoint(dNdX_[first + q], dV_[first + q], D_, U, &e, true);
    for (int a = 0; a < n_per_cell_; ++a)
      for (int b = 0; b < n_per_cell_; ++b)
        for (int i = 0; i < 3; ++i)
          for (int k = 0; k < 3; ++k)
            triplets.emplace_back(3 * cells_(c, a) + i, 3 * cells_(c, b) + k,
                                  0.5 * (e.tangent(3 * a + i, 3 * b + k) + e.tangent(3 * b + k, 3 * a + i)));
  });
  SparseMatrix K(n_dofs(), n_dofs());
  K.setFromTriplets(triplets.begin(), triplets.end());
  return K;
}

std::vector<std::pair<int, Eigen::VectorXd>> InterfaceRotationCompletion(
    const Eigen::MatrixXd& mesh_nodes, const Eigen::MatrixXd& mesh_shapes,
    const std::vector<Eigen::Vector3d>& interface_points, const Eigen::Vector3d& origin) {
  const int n = int(mesh_shapes.cols());
  const long n_nodes = mesh_nodes.rows();
  auto pair_index = [n](int j, int k) { return j * n - j * (j - 1) / 2 + (k - j); };  // j <= k
  std::vector<std::pair<int, Eigen::VectorXd>> fields;
  for (size_t k = 0; k < interface_points.size(); ++k) {
    const int first = 6 * int(k);
    for (int a = 0; a < 3; ++a)
      for (int b = a; b < 3; ++b) {
        const Eigen::Matrix3d Ea = Skew<double>(Eigen::Vector3d::Unit(a)), Eb = Skew<double>(Eigen::Vector3d::Unit(b));
        const Eigen::Matrix3d C = 0.25 * (Ea * Eb + Eb * Ea);  // sym(e_a~ e_b~) / 2
        Eigen::VectorXd W = Eigen::VectorXd::Zero(3 * n_nodes);
        for (long i = 0; i < n_nodes; ++i) {
          const double phi = mesh_shapes(3 * i, first);  // x component of interface k's u_x mode
          W.segment<3>(3 * i) = phi * C * (mesh_nodes.row(i).transpose() - origin);
        }
        W -= mesh_shapes.middleCols(first, 3) * (C * (interface_points[k] - origin));
        fields.emplace_back(pair_index(first + 3 + a, first + 3 + b), std::move(W));
      }
  }
  return fields;
}

namespace {

// Gathers one element's columns of node-major mesh fields (3 per node) into `element` (3 ne x k).
void Gather(const Eigen::MatrixXd& fields, const Eigen::MatrixXi& cells, long c, Eigen::MatrixXd& element) {
  const int ne = int(cells.cols());
  for (int a = 0; a < ne; ++a) element.middleRows(3 * a, 3) = fields.middleRows(3 * long(cells(c, a)), 3);
}

// The linear Voigt strains (6 x k) at a point of the element fields (3 ne x k), and the gradients.
void PointStrains(const Eigen::MatrixXd& element, const Eigen::MatrixXd& g, Eigen::MatrixXd& U,
                  std::vector<Eigen::Matrix3d>* G, Eigen::MatrixXd& L) {
  const int ne = int(g.rows());
  for (long j = 0; j < element.cols(); ++j) {
    for (int a = 0; a < ne; ++a) U.row(a) = element.block(3 * a, j, 3, 1).transpose();
    const Eigen::Matrix3d Gj = U.transpose() * g;
    if (G) (*G)[size_t(j)] = Gj;
    L.col(j) = LinearStrain(Gj);
  }
}

}  // namespace

// The completion's work with the basis vectors from `first` on, made zero: the fields W_f minus
// their K-orthogonal projection onto those vectors V, a = (V^T K V)^-1 V^T K W (both from the
// point strains, one pass over the mesh without the quadratic terms). Returns a (n - first x
// n_fields) with W'_f = W_f - V a_f.
Eigen::MatrixXd CompletionProjection(const SvkSolidMesh& solid, const Eigen::MatrixXd& mesh_shapes,
                                     const Eigen::MatrixXd& fields, int first) {
  const int n = int(mesh_shapes.cols()), nv = n - first, ne = solid.n_per_cell_, nf = int(fields.cols());
  const Eigen::MatrixXd V = mesh_shapes.rightCols(nv);
  Eigen::MatrixXd element(3 * ne, nv), field_element(3 * ne, nf), U(ne, 3), L(6, nv), Lf(6, nf);
  Eigen::MatrixXd K_vv = Eigen::MatrixXd::Zero(nv, nv), G = Eigen::MatrixXd::Zero(nv, nf);
  for (long c = solid.first_cell(); c < solid.end_cell(); ++c) {
    Gather(V, solid.cells_, c, element);
    Gather(fields, solid.cells_, c, field_element);
    for (int q = 0; q < solid.points_per_cell_; ++q) {
      const size_t point = size_t(c - solid.first_cell()) * solid.points_per_cell_ + q;
      PointStrains(element, solid.dNdX_[point], U, nullptr, L);
      PointStrains(field_element, solid.dNdX_[point], U, nullptr, Lf);
      const Eigen::MatrixXd DL = solid.D_ * L;
      K_vv.noalias() += solid.dV_[point] * L.transpose() * DL;
      G.noalias() += solid.dV_[point] * DL.transpose() * Lf;
    }
  }
  SumOverRanks(K_vv, solid.held_);
  SumOverRanks(G, solid.held_);
  return Eigen::MatrixXd(0.5 * (K_vv + K_vv.transpose())).ldlt().solve(G);
}

ReducedPolynomial ReduceSvk(const SvkSolidMesh& solid, const Eigen::MatrixXd& mesh_shapes,
                            const std::vector<std::pair<int, Eigen::VectorXd>>& pair_fields,
                            const PolynomialRequest& request) {
  const int n = int(mesh_shapes.cols()), P = n * (n + 1) / 2, ne = solid.n_per_cell_;
  const int n_stress = request.stress_fields ? int(request.stress_fields->cols()) : 0;
  const int n_fields = int(pair_fields.size());
  Eigen::MatrixXd fields(mesh_shapes.rows(), n_fields);
  for (int f = 0; f < n_fields; ++f) fields.col(f) = pair_fields[size_t(f)].second;
  const int first = request.static_coordinates;
  const bool project = n_fields > 0 && first >= 0 && first < n;
  const Eigen::MatrixXd a = project ? CompletionProjection(solid, mesh_shapes, fields, first) : Eigen::MatrixXd();
  PolynomialAccumulator accumulator(n, request.cubic, n_stress);
  Eigen::MatrixXd stress_element(3 * ne, n_stress), L_stress(6, n_stress), L_fields(6, n_fields);
  const Eigen::Matrix<double, 6, 6> C = solid.D_.llt().matrixU();  // D = C^T C
  std::vector<Eigen::Matrix3d> G(static_cast<size_t>(n));
  Eigen::MatrixXd L(6, n), Q(6, P), Q_plain, U(ne, 3);
  Eigen::MatrixXd element(3 * ne, n), field_element(3 * ne, n_fields);
  for (long c = solid.first_cell(); c < solid.end_cell(); ++c) {
    Gather(mesh_shapes, solid.cells_, c, element);
    Gather(fields, solid.cells_, c, field_element);
    if (n_stress > 0) Gather(*request.stress_fields, solid.cells_, c, stress_element);
    for (int q = 0; q < solid.points_per_cell_; ++q) {
      const size_t point = size_t(c - solid.first_cell()) * solid.points_per_cell_ + q;
      const Eigen::MatrixXd& g = solid.dNdX_[point];
      PointStrains(element, g, U, &G, L);
      int p = 0;
      for (int j = 0; j < n; ++j)
        for (int k = j; k < n; ++k, ++p) {
          const Eigen::Matrix3d S =
              0.5 * (G[size_t(j)].transpose() * G[size_t(k)] + G[size_t(k)].transpose() * G[size_t(j)]);
          Q.col(p) << S(0, 0), S(1, 1), S(2, 2), 2 * S(1, 2), 2 * S(0, 2), 2 * S(0, 1);
        }
      const bool separate = n_fields > 0 && n_stress > 0;
      if (separate) Q_plain = Q;
      if (n_fields > 0) {
        PointStrains(field_element, g, U, nullptr, L_fields);
        if (project) L_fields.noalias() -= L.rightCols(n - first) * a;
        for (int f = 0; f < n_fields; ++f) Q.col(pair_fields[size_t(f)].first) += 2 * L_fields.col(f);
      }
      if (n_stress > 0) PointStrains(stress_element, g, U, nullptr, L_stress);
      accumulator.Add(solid.dV_[point], C, L, Q, n_stress > 0 ? &L_stress : nullptr, separate ? &Q_plain : nullptr);
    }
  }
  ReducedPolynomial r = accumulator.Finish();
  for (Eigen::MatrixXd* X : {&r.K, &r.A, &r.B, &r.S})
    SumOverRanks(*X, solid.held_);  // (the ranks' shares of the elements)
  return r;
}

PolynomialAccumulator::PolynomialAccumulator(int n, bool cubic, int n_fields) : cubic_(cubic) {
  const int P = n * (n + 1) / 2;
  r_.K = Eigen::MatrixXd::Zero(n, n);
  r_.A = Eigen::MatrixXd::Zero(n, P);
  r_.S = Eigen::MatrixXd::Zero(n_fields, P);
  if (cubic_) {
    r_.B = Eigen::MatrixXd::Zero(P, P);
    stack_.resize(6 * kPointsPerBlock, P);
  }
}

void PolynomialAccumulator::Add(double dV, const Eigen::Matrix<double, 6, 6>& C, const Eigen::MatrixXd& L,
                                const Eigen::MatrixXd& Q, const Eigen::MatrixXd* L_fields,
                                const Eigen::MatrixXd* Q_fields) {
  const Eigen::MatrixXd CL = C * L, CQ = C * Q;
  r_.K.noalias() += dV * CL.transpose() * CL;
  r_.A.noalias() += (0.5 * dV) * CL.transpose() * CQ;
  if (L_fields && r_.S.rows() > 0) {
    r_.S.noalias() += dV * (C * *L_fields).transpose() * (Q_fields ? Eigen::MatrixXd(C * *Q_fields) : CQ);
  }
  if (!cubic_) return;
  // B gathers (C Q)^T (C Q) dV / 8, stacked into blocks of rows (one BLAS product each).
  stack_.middleRows(6 * stacked_, 6) = std::sqrt(dV / 8) * CQ;
  if (++stacked_ == kPointsPerBlock) Flush();
}

void PolynomialAccumulator::Flush() {
  if (stacked_ == 0) return;
  // B += Y^T Y: the stiffening stage's large product (points x 528 columns at 32 modes), in BLAS.
  Gemm(stack_.topRows(6 * stacked_), true, stack_.topRows(6 * stacked_), false, r_.B, 1.0, 1.0);
  stacked_ = 0;
}

ReducedPolynomial PolynomialAccumulator::Finish() {
  if (cubic_) Flush();
  r_.K = 0.5 * (r_.K + r_.K.transpose()).eval();
  if (cubic_) r_.B = 0.5 * (r_.B + r_.B.transpose()).eval();
  return std::move(r_);
}

NonlinearStaticResult SolveNonlinearStatic(const NonlinearModel& solid, const SparseMatrix& T_in,
                                           const std::vector<int>& prescribed_dofs,
                                           const Eigen::VectorXd& prescribed_values, const Eigen::VectorXd& f_ext,
                                           int steps, double tolerance, int max_iterations,
                                           const Eigen::VectorXd* u_start) {
  SparseMatrix T = T_in;
  if (T.size() == 0) {
    T.resize(solid.n_dofs(), solid.n_dofs());
    T.setIdentity();
  }
  const long n = T.cols();
  std::vector<char> fixed(size_t(n), 0);
  for (int d : prescribed_dofs) fixed[size_t(d)] = 1;
  std::vector<int> free;
  for (long d = 0; d < n; ++d)
    if (!fixed[size_t(d)]) free.push_back(int(d));
  // Selection of the free DOFs: S (n x n_free).
  SparseMatrix S(n, long(free.size()));
  {
    std::vector<Eigen::Triplet<double>> t;
    for (size_t k = 0; k < free.size(); ++k) t.emplace_back(free[k], int(k), 1.0);
    S.setFromTriplets(t.begin(), t.end());
  }
  const SparseMatrix TS = T * S;
  NonlinearStaticResult result;
  Eigen::VectorXd u = u_start ? *u_start : Eigen::VectorXd::Zero(n);  // free DOFs start there
  for (int step = 1; step <= steps; ++step) {
    const double lambda = double(step) / steps;
    for (size_t k = 0; k < prescribed_dofs.size(); ++k) u[prescribed_dofs[k]] = lambda * prescribed_values[long(k)];
    int it = 0;
    Eigen::VectorXd r;
    double last_step = HUGE_VAL;  // ||du|| of the last Newton correction
    for (;; ++it) {
      const Eigen::VectorXd f_model = T.transpose() * solid.Force(T * u);
      r = f_model - lambda * f_ext;
      const Eigen::VectorXd r_free = S.transpose() * r;
      const double scale = std::max({(lambda * f_ext).norm(), (r - S * r_free).norm(), 1e-300});
      if (!std::isfinite(r_free.norm())) {
        result.converged = false;
        result.message = "residual is not finite at load factor " + std::to_string(lambda);
        return result;
      }
      // Converged: the residual, or (when round-off in the large internal forces of a stiff
      // part keeps it above that) the displacement correction at round-off level.
      if (it > 0 && (r_free.norm() <= tolerance * scale || last_step <= 1e-12 * u.norm())) break;
      if (it == max_iterations) {
        result.converged = false;
        char buffer[200];
        std::snprintf(buffer, sizeof buffer,
                      "no convergence at load factor %.4g after %d Newton iterations (residual %.3g of %.3g)", lambda,
                      it, r_free.norm(), scale);
        result.message = buffer;
        return result;
      }
      const SparseMatrix K = SparseMatrix(TS.transpose() * solid.Tangent(T * u) * TS);
      Eigen::SimplicialLDLT<SparseMatrix> solver(K);
      if (solver.info() != Eigen::Success) {
        result.converged = false;
        result.message = "singular tangent at load factor " + std::to_string(lambda);
        return result;
      }
      const Eigen::VectorXd du = S * solver.solve(r_free);
      last_step = du.norm();
      u -= du;
    }
    result.load_factor.push_back(lambda);
    result.u.push_back(u);
    result.reaction.push_back(r);
    result.iterations.push_back(it);
  }
  return result;
}

}  // namespace femb
