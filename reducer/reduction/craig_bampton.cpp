#include "reducer/reduction/craig_bampton.h"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <unordered_map>

#include "reducer/linalg/dense_products.h"
#include "reducer/linalg/generalized_eigen.h"
#include "reducer/linalg/interior_solver.h"
#include "reducer/linalg/shared_columns.h"
#include "reducer/reduction/interior_blocks.h"

namespace femb {
namespace {

// Block size of the shift-invert Lanczos: right-hand sides per pass over the factor.
constexpr int kLanczosBlock = 8;
// Residual tolerance of the fixed-interface modes, ||K x - lambda M x|| relative: the Ritz
// values are then exact to ~tol^2 and the reduced matrices are the Galerkin projection on the
// computed vectors whatever their accuracy.
constexpr double kLanczosTolerance = 1e-8;

// Solids: the model DOF fields that the mesh map T sends closest to the given mesh fields
// (3 rows per mesh node): least squares, (T^T T) x = T^T f.
Eigen::MatrixXd ModelFieldsFromMesh(const FeModel& model, const Eigen::MatrixXd& mesh_fields) {
  const SparseMatrix& T = model.mesh_map;
  const SparseMatrix TtT = SparseMatrix(T.transpose() * T);
  Eigen::SimplicialLDLT<SparseMatrix> normal(TtT);
  return normal.solve(Eigen::MatrixXd(T.transpose() * mesh_fields));
}

}  // namespace

Eigen::MatrixXd RigidFields(const FeModel& model) {
  const long n = model.n_dofs();
  auto rigid = [](const Eigen::Vector3d& x, bool with_rotation) {
    Eigen::MatrixXd r = Eigen::MatrixXd::Zero(with_rotation ? 6 : 3, 6);
    r.topLeftCorner<3, 3>().setIdentity();
    r.block<3, 3>(0, 3) << 0, x.z(), -x.y(), -x.z(), 0, x.x(), x.y(), -x.x(), 0;  // theta x x = -x~ theta
    if (with_rotation) r.bottomRightCorner<3, 3>().setIdentity();
    return r;
  };
  if (!model.dof_component.empty()) {  // imported: each DOF knows its point and component
    Eigen::MatrixXd R(n, 6);
    for (long d = 0; d < n; ++d) R.row(d) = rigid(model.dof_point[size_t(d)], true).row(model.dof_component[size_t(d)]);
    return R;
  }
  if (model.mesh_map.size() == 0) {  // beams: 6 DOFs per node
    Eigen::MatrixXd R(n, 6);
    for (long k = 0; k < model.n_nodes(); ++k) R.middleRows(6 * k, 6) = rigid(model.nodes.row(k).transpose(), true);
    return R;
  }
  // Solids: the mesh field is rigid; the model field is the one T maps onto it (exact: T maps
  // rigid model motions, RBE2 nodes included, to rigid mesh motions).
  Eigen::MatrixXd R_mesh(model.mesh_map.rows(), 6);
  for (long k = 0; k < model.n_nodes(); ++k) R_mesh.middleRows(3 * k, 3) = rigid(model.nodes.row(k).transpose(), false);
  return ModelFieldsFromMesh(model, R_mesh);
}

Eigen::Matrix<double, 3, 12> InertiaFieldAt(const Eigen::Vector3d& x) {
  Eigen::Matrix<double, 3, 12> f = Eigen::Matrix<double, 3, 12>::Zero();
  f.leftCols<3>().setIdentity();
  for (int i = 0; i < 3; ++i) {
    f.col(3 + i) = Eigen::Vector3d(Eigen::Vector3d::Unit(i)).cross(x);  // alpha_i e_i x x
    f.col(6 + i) = x[i] * Eigen::Vector3d::Unit(i) - x;                 // (e_i e_i^T - 1) x
  }
  f.col(9) << x.y(), x.x(), 0.0;   // (e_x e_y^T + e_y e_x^T) x
  f.col(10) << x.z(), 0.0, x.x();  // (e_x e_z^T + e_z e_x^T) x
  f.col(11) << 0.0, x.z(), x.y();  // (e_y e_z^T + e_z e_y^T) x
  return f;
}

Eigen::MatrixXd InertiaFields(const FeModel& model) {
  const long n = model.n_dofs();
  if (model.mesh_map.size() == 0) {  // beams: 6 DOFs per node; rotations follow alpha
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, 12);
    for (long k = 0; k < model.n_nodes(); ++k) {
      A.middleRows(6 * k, 3) = InertiaFieldAt(model.nodes.row(k).transpose());
      A.block(6 * k + 3, 3, 3, 3).setIdentity();
    }
    return A;
  }
  // Solids: exact on the free mesh nodes; a least-squares rigid fit on an RBE2 face, whose DOFs
  // the load cases hold anyway.
  Eigen::MatrixXd A_mesh(model.mesh_map.rows(), 12);
  for (long k = 0; k < model.n_nodes(); ++k)
    A_mesh.middleRows(3 * k, 3) = InertiaFieldAt(model.nodes.row(k).transpose());
  return ModelFieldsFromMesh(model, A_mesh);
}

namespace {

// S_a Phi for the skew matrices S_a of e_a on every DOF triple (InertiaInvariants), on the whole
// of the model's DOFs.
std::array<Eigen::MatrixXd, 3> TurnedFields(const FeModel& model, const Eigen::MatrixXd& shapes) {
  const long n = shapes.rows();
  std::array<Eigen::MatrixXd, 3> turned;
  std::array<Eigen::Matrix3d, 3> S;  // S_a v = e_a x v
  for (int a = 0; a < 3; ++a) {
    const Eigen::Vector3d e = Eigen::Vector3d::Unit(a);
    S[size_t(a)] << 0, -e.z(), e.y(), e.z(), 0, -e.x(), -e.y(), e.x(), 0;
    turned[size_t(a)] = Eigen::MatrixXd::Zero(n, shapes.cols());
  }
  if (model.dof_node.empty()) {
    // femb's own models: every DOF belongs to a triple of vector components in part axes
    // (beams: 6 per node; solids: 3 per free mesh node, then 6 per RBE2 interface).
    for (int a = 0; a < 3; ++a)
      for (long t = 0; t + 2 < n; t += 3) turned[size_t(a)].middleRows(t, 3) = S[size_t(a)] * shapes.middleRows(t, 3);
  } else {
    // Imported models: the DOFs of one node and kind (translation, rotation) are the components
    // of one vector, in any order and possibly incomplete (a missing component is zero: a node
    // with two translations in a planar model, a shell's five rotations).
    std::unordered_map<int, std::array<int, 6>> component_dof;
    for (long d = 0; d < n; ++d) {
      auto [it, added] = component_dof.try_emplace(model.dof_node[size_t(d)]);
      if (added) it->second.fill(-1);
      it->second[size_t(model.dof_component[size_t(d)])] = int(d);
    }
    for (long d = 0; d < n; ++d) {
      const int c = model.dof_component[size_t(d)];
      const int kind = c / 3;
      const std::array<int, 6>& dofs = component_dof.at(model.dof_node[size_t(d)]);
      for (int j = 0; j < 3; ++j) {
        const int from = dofs[size_t(3 * kind + j)];
        if (from < 0) continue;
        for (int a = 0; a < 3; ++a) {
          const double s = S[size_t(a)](c % 3, j);
          if (s != 0.0) turned[size_t(a)].row(d) += s * shapes.row(from);
        }
      }
    }
  }
  return turned;
}

}  // namespace

void InertiaInvariants(const FeModel& model, const Eigen::MatrixXd& shapes, std::vector<Eigen::MatrixXd>* gamma,
                       std::vector<Eigen::MatrixXd>* xi) {
  // On MPI ranks a rank's rows are whole DOF triples where they start at one (a solid's METIS
  // parts: 3 DOFs per node, the RBE2 interfaces' 6 after them): turned on its own rows; otherwise
  // (an even split of a beam's or an imported model's DOFs) turned whole and its rows kept.
  const ColumnShare& rows = model.columns;
  const bool own_triples = rows.whole() || (model.dof_node.empty() && rows.first % 3 == 0 && rows.count % 3 == 0);
  std::array<Eigen::MatrixXd, 3> turned =
      own_triples ? TurnedFields(model, shapes) : TurnedFields(model, GatherRows(shapes, rows));
  if (!own_triples)
    for (Eigen::MatrixXd& t : turned) t = HeldRows(t, rows);
  gamma->clear();
  xi->clear();
  std::array<Eigen::MatrixXd, 3> M_turned;
  for (int a = 0; a < 3; ++a) {
    M_turned[size_t(a)] = SharedTimesRows(model.M, turned[size_t(a)], rows);
    gamma->push_back(TransposeTimesRows(shapes, M_turned[size_t(a)], rows));
  }
  const int pairs[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};
  for (const auto& ab : pairs) {
    Eigen::MatrixXd X = TransposeTimesRows(turned[size_t(ab[0])], M_turned[size_t(ab[1])], rows);
    if (ab[0] == ab[1]) X = 0.5 * (X + X.transpose()).eval();
    xi->push_back(std::move(X));
  }
}

std::vector<int> InteriorDofs(const FeModel& model) {
  std::vector<char> is_boundary(model.n_dofs(), 0);
  for (const auto& dofs : model.interface_dofs) {
    for (FullDof d : dofs) is_boundary[d.value] = 1;
  }
  std::vector<int> interior;
  for (int d = 0; d < model.n_dofs(); ++d) {
    if (!is_boundary[d]) interior.push_back(d);
  }
  return interior;
}

namespace {

// The reduced coordinates' kinds: 6 per interface in order, then the modes. A DOF interface's six
// coordinates are boundary DOFs b; a distributing (RBE3) interface's are constraint rows q = W u
// on the interior DOFs, W^T (n_i x n_c) sparse: nonzero only on the coupled node sets.
// `interior_share`: the interior columns this rank holds of K_ii and M_ii (the interior DOFs among
// the model's columns it holds; all on one process).
struct InterfacePartition {
  std::vector<int> boundary, boundary_coordinate, constraint_coordinate, interior;
  std::vector<int> interior_index, boundary_index;  ///< per full DOF, -1 elsewhere
  SparseMatrix Wt;
  int n_b = 0, n_i = 0, n_c = 0;
  ColumnShare interior_share;
  /// The interior rows this rank holds of the dense blocks while the factor lives: held_rows()
  /// from held_first().
  long held_rows() const { return interior_share.whole() ? n_i : interior_share.count; }
  long held_first() const { return interior_share.whole() ? 0 : interior_share.first; }
};

// The partition of the model's DOFs by its interfaces; false with *message when an RBE3
// interface weights a DOF of another interface's coupling.
bool PartitionInterfaces(const FeModel& model, InterfacePartition& p, std::string* message) {
  const int n = int(model.n_dofs());
  const int n_interfaces = int(model.interface_names.size());
  std::vector<const SparseMatrix*> weights;
  for (int k = 0; k < n_interfaces; ++k) {
    const bool constrained = k < int(model.interface_weights.size()) && model.interface_weights[k].rows() > 0;
    if (constrained) {
      weights.push_back(&model.interface_weights[k]);
      for (int d = 0; d < 6; ++d) p.constraint_coordinate.push_back(6 * k + d);
      continue;
    }
    for (int d = 0; d < 6; ++d) {
      p.boundary.push_back(model.interface_dofs[k][d].value);
      p.boundary_coordinate.push_back(6 * k + d);
    }
  }
  p.interior = InteriorDofs(model);
  p.n_b = int(p.boundary.size()), p.n_i = int(p.interior.size()), p.n_c = int(p.constraint_coordinate.size());
  p.interior_index.assign(size_t(n), -1);
  p.boundary_index.assign(size_t(n), -1);
  for (int k = 0; k < p.n_i; ++k) p.interior_index[p.interior[k]] = k;
  for (int k = 0; k < p.n_b; ++k) p.boundary_index[p.boundary[k]] = k;
  if (!model.columns.whole()) {  // (interior DOFs ascending: the held ones are a range of them)
    const auto first = std::lower_bound(p.interior.begin(), p.interior.end(), model.columns.first);
    const auto end = std::lower_bound(p.interior.begin(), p.interior.end(), model.columns.end(n));
    p.interior_share = {long(first - p.interior.begin()), long(end - first)};
  }
  p.Wt.resize(p.n_i, p.n_c);
  std::vector<Eigen::Triplet<double>> entries;
  int row = 0;
  for (const SparseMatrix* W : weights) {
    for (int col = 0; col < W->outerSize(); ++col)
      for (SparseMatrix::InnerIterator it(*W, col); it; ++it) {
        if (p.interior_index[col] < 0) {
          *message = "an RBE3 interface weights a DOF of another interface's coupling";
          return false;
        }
        entries.emplace_back(p.interior_index[col], row + int(it.row()), it.value());
      }
    row += 6;
  }
  p.Wt.setFromTriplets(entries.begin(), entries.end());
  return true;
}

// When no interface is a DOF interface (every interface distributing), the matrix factored is
// the augmented F = K_ii + a W_1^T W_1, W_1 the six (unit-normalized) constraint rows of the
// first RBE3 interface: K_ii alone still has the six rigid-body modes that only the constraints
// W u = q remove, and W_1 alone removes them. Every solve is on W x = 0 or W x = e_j, where F and
// K_ii give the same answer: on W x = 0, F x = K_ii x; on W x = e_j the extra a W_1^T (W_1 x) is a
// constraint force that the multipliers absorb. So the static modes, the fixed-interface modes and
// the modal derivatives are those of K_ii exactly, at any scale of the part (no shift, no
// iteration); a only sets the conditioning: the mean diagonal of K_ii over the DOFs W_1 weights.
// K_ii shared by columns: the diagonal summed over the ranks, the augmentation in the held columns.
SparseMatrix Augmented(const SparseMatrix& K_ii, const SparseMatrix& Wt, const ColumnShare& held) {
  const int n_i = int(K_ii.rows());
  Eigen::MatrixXd W1 = Eigen::MatrixXd(Wt.leftCols(6));  // n_i x 6 (dense columns, sparse support)
  for (int c = 0; c < 6; ++c) W1.col(c) /= std::max(W1.col(c).norm(), 1e-300);
  double diagonal = 0.0;
  int touched = 0;
  std::vector<Eigen::Triplet<double>> entries;
  std::vector<int> support;
  for (int j = 0; j < n_i; ++j) {
    if (W1.row(j).squaredNorm() == 0.0) continue;
    support.push_back(j);
    diagonal += K_ii.coeff(j, j);
    ++touched;
  }
  Eigen::Matrix<double, 1, 1> summed(diagonal);
  SumOverRanks(summed, held);
  diagonal = summed(0, 0);
  const double a = touched > 0 ? diagonal / touched : 1.0;
  for (int i : support)
    for (int j : support) {
      if (!held.Holds(j)) continue;
      const double v = a * W1.row(i).dot(W1.row(j));
      if (v != 0.0) entries.emplace_back(i, j, v);
    }
  SparseMatrix augmentation(n_i, n_i);
  augmentation.setFromTriplets(entries.begin(), entries.end());
  return K_ii + augmentation;
}

// Solves on the constrained space W x = 0 (Lagrange multipliers eliminated through the 6r x 6r
// Schur complement S = W F^-1 W^T, F the factored matrix):
//   F x + W^T mu = z, W x = 0   =>   x = F^-1 z - Y S^-1 W F^-1 z,  Y = F^-1 W^T.
// On this rank's rows (`share` of the interior; all on one process) as the factor's solves: the
// products W x are each rank's part, summed.
class ConstrainedSolver {
 public:
  ConstrainedSolver(InteriorSolver& factor, const SparseMatrix& Wt, const ColumnShare& share)
      : factor_(factor),
        share_(share),
        Wt_(share.whole() ? Wt : SparseMatrix(Wt.middleRows(share.first, share.count))),
        Y_(Wt.cols() > 0 ? factor.Solve(Eigen::MatrixXd(Wt_)) : Eigen::MatrixXd(Wt_.rows(), 0)),
        S_(Constraints(Y_)) {}
  Eigen::MatrixXd Solve(const Eigen::MatrixXd& z) const {
    Eigen::MatrixXd x = factor_.Solve(z);
    if (Wt_.cols() > 0) x -= Y_ * S_.solve(Constraints(x));
    return x;
  }
  // The distributing interfaces' static modes: their six coordinates set to unit values
  // (W x = e_j) at least strain energy, x0 = Y S^-1 (stationary for F, and so for K_ii).
  Eigen::MatrixXd UnitConstraintModes() const {
    return Y_ * S_.solve(Eigen::MatrixXd::Identity(Wt_.cols(), Wt_.cols()));
  }

 private:
  // W x for x held as this rank's rows.
  Eigen::MatrixXd Constraints(const Eigen::MatrixXd& x) const {
    Eigen::MatrixXd Wx = Wt_.transpose() * x;
    SumOverRanks(Wx, share_);
    return Wx;
  }

  InteriorSolver& factor_;
  const ColumnShare share_;
  const SparseMatrix Wt_;  ///< this rank's rows of W^T
  const Eigen::MatrixXd Y_;
  const Eigen::LDLT<Eigen::MatrixXd> S_;
};

// This rank's interior rows of full-DOF fields f (n x k), or of f's rows from model DOF
// `first_row` on (this rank's rows of the model's DOFs).
Eigen::MatrixXd HeldInteriorRows(const InterfacePartition& p, const Eigen::MatrixXd& f, long first_row = 0) {
  Eigen::MatrixXd out(p.held_rows(), f.cols());
  for (long k = 0; k < out.rows(); ++k) out.row(k) = f.row(p.interior[size_t(p.held_first() + k)] - first_row);
  return out;
}

// Static modes: a DOF interface moved by a unit motion with the others held (K_ii x = -K_ib,
// W x = 0), into Psi_b; a distributing interface's, into Psi_c (UnitConstraintModes).
void StaticModes(const FeModel& model, const InterfacePartition& p, const SparseMatrix& K_ib,
                 const ConstrainedSolver& solver, Eigen::MatrixXd& Psi_b, Eigen::MatrixXd& Psi_c) {
  // (this rank's rows of K_ib: the ranks hold its columns, the boundary DOFs', in pieces)
  const ColumnShare& held = p.interior_share;
  const long rows = p.held_rows();
  const Eigen::MatrixXd K_ib_rows =
      p.n_b > 0 ? HeldRows(SumSparseOverRanks(K_ib, held), held) : Eigen::MatrixXd(rows, 0);
  Psi_b = p.n_b > 0 ? Eigen::MatrixXd(-solver.Solve(K_ib_rows)) : Eigen::MatrixXd(rows, 0);
  // Rigid motions exactly: mathematically the static modes reproduce them (Psi_b R_b = R_i for
  // the rigid fields R); in floating point only to cond(K_ii) times the round-off of K R = 0,
  // which a thin part (a 0.5 mm leaf: 3e-8) makes visible in Phi_CB Phi_rig0 = 1. A rank-6
  // correction Psi_b += (R_i - Psi_b R_b) (R_b^T R_b)^-1 R_b^T restores it to round-off; it
  // changes the static modes by that residual only. (DOF interfaces only; row by row.)
  if (p.n_b > 0 && p.n_c == 0) {
    const Eigen::MatrixXd R = RigidFields(model);
    Eigen::MatrixXd R_b(p.n_b, 6);
    for (int k = 0; k < p.n_b; ++k) R_b.row(k) = R.row(p.boundary[k]);
    const Eigen::MatrixXd R_i = HeldInteriorRows(p, R);
    const Eigen::MatrixXd G = R_b.transpose() * R_b;
    Psi_b += (R_i - Psi_b * R_b) * G.ldlt().solve(R_b.transpose());
  }
  Psi_c.resize(rows, p.n_c);
  if (p.n_c > 0) Psi_c = solver.UnitConstraintModes();
}

// The full fields of the reduced coordinates on the model DOFs [first, first + rows): unit
// boundary DOFs, the static modes on the interior, the fixed-interface modes (n_cb: 6 per
// interface and the m modes), then the derivatives. The blocks' rows are the interior's from
// `interior_first` on.
Eigen::MatrixXd ShapesOnRows(const InterfacePartition& p, long first, long rows, long interior_first,
                             const Eigen::MatrixXd& Psi_b, const Eigen::MatrixXd& Psi_c, const Eigen::MatrixXd& Phi_i,
                             const Eigen::MatrixXd& Theta, int n_cb) {
  const long m = Phi_i.cols(), d = Theta.cols();
  Eigen::MatrixXd shapes = Eigen::MatrixXd::Zero(rows, n_cb + d);
  for (long g = first; g < first + rows; ++g) {
    const long row = g - first;
    if (const int b = p.boundary_index[size_t(g)]; b >= 0) {
      shapes(row, p.boundary_coordinate[size_t(b)]) = 1.0;
      continue;
    }
    const long k = p.interior_index[size_t(g)] - interior_first;
    for (int j = 0; j < p.n_b; ++j) shapes(row, p.boundary_coordinate[size_t(j)]) = Psi_b(k, j);
    for (int j = 0; j < p.n_c; ++j) shapes(row, p.constraint_coordinate[size_t(j)]) = Psi_c(k, j);
    if (m > 0) shapes.row(row).segment(n_cb - m, m) = Phi_i.row(k);
    if (d > 0) shapes.row(row).tail(d) = Theta.row(k);
  }
  return shapes;
}

// The model DOFs this rank holds the rows of after the factor: its columns (all on one process).
long FirstModelRow(const FeModel& model) { return model.columns.whole() ? 0 : model.columns.first; }
long ModelRows(const FeModel& model) { return model.columns.whole() ? model.n_dofs() : model.columns.count; }

// Pairs whose (dK/dq_j) phi_i are evaluated at a time: the n x pairs block of them is never held
// whole (20 modes' pairs are 210 columns).
constexpr size_t kDerivativePairsPerStep = 16;

// x^T y for x and y held as each rank's rows of the interior.
double RowsDot(const InterfacePartition& p, const Eigen::VectorXd& x, const Eigen::VectorXd& y) {
  Eigen::Matrix<double, 1, 1> d(x.dot(y));
  SumOverRanks(d, p.interior_share);
  return d(0, 0);
}

// X^T y for X and y held as each rank's rows of the interior (Eigen's product: a vector).
Eigen::VectorXd RowsCoefficients(const InterfacePartition& p, const Eigen::Ref<const Eigen::MatrixXd>& X,
                                 const Eigen::VectorXd& y) {
  Eigen::VectorXd c = X.transpose() * y;
  SumOverRanks(c, p.interior_share);
  return c;
}

// X^T Y for X and Y held as each rank's rows of the interior (dense_products' product).
Eigen::MatrixXd RowsTransposeTimes(const InterfacePartition& p, const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y) {
  return TransposeTimesRows(X, Y, p.interior_share);
}

// Modal derivatives: interior solves with the interfaces held, deflated against the modes and
// the derivatives kept (M_ii inner product, twice), normalized; a derivative that deflation
// leaves below the request's tolerance of its norm is dropped. The kept pairs into r. Phi_i and
// the derivatives: this rank's rows; `shapes`: this rank's rows of the Craig-Bampton shapes, those
// of the model's DOFs from `first_row` on (all of them on one process).
Eigen::MatrixXd ModalDerivatives(const InterfacePartition& p, const SparseMatrix& M_ii, const Eigen::MatrixXd& Phi_i,
                                 const Eigen::MatrixXd& shapes, long first_row, const DerivativeRequest& derivatives,
                                 const ConstrainedSolver& solver, CraigBamptonResult& r) {
  const int m = int(Phi_i.cols());
  const auto M_ii_times = [&](const Eigen::VectorXd& v) {
    return Eigen::VectorXd(SharedTimesRows(M_ii, v, p.interior_share));
  };
  const std::vector<std::pair<int, int>>& pairs = derivatives.pairs;
  Eigen::MatrixXd z(p.held_rows(), long(pairs.size()));
  for (size_t at = 0; at < pairs.size(); at += kDerivativePairsPerStep) {
    const size_t end = std::min(pairs.size(), at + kDerivativePairsPerStep);
    const std::vector<std::pair<int, int>> step(pairs.begin() + long(at), pairs.begin() + long(end));
    z.middleCols(long(at), long(step.size())) =
        -HeldInteriorRows(p, derivatives.stiffness_derivative(shapes, step), first_row);
  }
  const Eigen::MatrixXd raw = solver.Solve(z);
  Eigen::MatrixXd Theta(p.held_rows(), raw.cols());
  int kept = 0;
  for (long c = 0; c < raw.cols(); ++c) {
    Eigen::VectorXd v = raw.col(c);
    const double before = std::sqrt(std::max(RowsDot(p, v, M_ii_times(v)), 0.0));
    for (int pass = 0; pass < 2; ++pass) {
      if (m > 0) v -= Phi_i * RowsCoefficients(p, Phi_i, M_ii_times(v));
      if (kept > 0) v -= Theta.leftCols(kept) * RowsCoefficients(p, Theta.leftCols(kept), M_ii_times(v));
    }
    const double after = std::sqrt(std::max(RowsDot(p, v, M_ii_times(v)), 0.0));
    if (!(before > 0) || after <= derivatives.tolerance * before) continue;
    Theta.col(kept++) = v / after;
    r.derivative_pairs.push_back(pairs[size_t(c)]);
  }
  Theta.conservativeResize(p.held_rows(), kept);
  return Theta;
}

// Interior fields (this rank's rows of the interior) on the model DOFs this rank holds the rows of,
// zero on the boundary DOFs.
Eigen::MatrixXd FieldsOnModelRows(const FeModel& model, const InterfacePartition& p, const Eigen::MatrixXd& u) {
  const long first = FirstModelRow(model);
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(ModelRows(model), u.cols());
  for (long row = 0; row < out.rows(); ++row) {
    const int k = p.interior_index[size_t(first + row)];
    if (k >= 0) out.row(row) = u.row(k - p.held_first());
  }
  return out;
}

// Inertia load cases: D'Alembert loads f = -M A_k on the interior, interfaces held; the part the
// basis carries through its own coordinates is removed. That part is the static response of the
// internal coordinates, eta = (V^T K_ii V)^-1 V^T f with V = [Phi_i Theta]: the K_ii-orthogonal
// projection u - V eta (V^T K_ii (u - V eta) = 0). For the modes alone it is their M_ii-orthogonal
// projection (Phi^T K = Lambda Phi^T M); the derivatives are not eigenvectors, and with the M_ii
// projection the stress they carry was counted twice or lost: a rotating cantilever with the
// derivatives of its modes' pairs was 21% stiff (beams) to 400% (a TET10 bar) in its bending
// frequency. Given this rank's rows of the loads' interior f_i = (-M A_k)_i (and of Phi_i and
// Theta); its rows of the interior fields (n_i x 12).
Eigen::MatrixXd InertiaDisplacements(const InterfacePartition& p, const SparseMatrix& K_ii,
                                     const Eigen::MatrixXd& Phi_i, const Eigen::MatrixXd& Theta,
                                     const Eigen::MatrixXd& f_i, const ConstrainedSolver& solver) {
  Eigen::MatrixXd u = solver.Solve(f_i);  // K_ii u = f_i on W u = 0
  const long m = Phi_i.cols(), d = Theta.cols();
  if (m + d > 0) {
    Eigen::MatrixXd V(p.held_rows(), m + d);
    V << Phi_i, Theta;
    const Eigen::MatrixXd K_r = RowsTransposeTimes(p, V, SharedTimesRows(K_ii, V, p.interior_share));
    u -= V * Eigen::MatrixXd(0.5 * (K_r + K_r.transpose())).ldlt().solve(RowsTransposeTimes(p, V, f_i));
  }
  return u;
}

// Projection K_r = Phi^T K Phi, M_r = Phi^T M Phi with Phi the full fields of the reduced
// coordinates (the Craig-Bampton shapes, then the derivatives; this rank's rows of them on MPI
// ranks): a Galerkin projection whatever the accuracy of the vectors (the static and modal blocks
// of K_r are K-orthogonal and Phi_i^T K Phi_i = Lambda up to the eigen solve's residual;
// femb-inspect shows both).
void Project(const FeModel& model, Eigen::MatrixXd shapes, CraigBamptonResult& r) {
  r.shapes = std::move(shapes);
  r.K = RowsCongruence(model.K, r.shapes, model.columns);
  r.M = RowsCongruence(model.M, r.shapes, model.columns);
  r.K = 0.5 * (r.K + r.K.transpose()).eval();
  r.M = 0.5 * (r.M + r.M.transpose()).eval();
}

// The factorization's progress line.
std::string FactorizationDetail(const FactorizationInfo& f, int n_i) {
  return Format("%.0f interior DOFs, factor %.3g MB, %.3g GFLOP, %.2f GFLOP/s", n_i, f.factor_bytes / 1e6,
                f.flops / 1e9, f.flops / 1e9 / std::max(f.numeric_seconds, 1e-9)) +
         Format(" (numeric %.3g s; ordering %.3g s, ", f.numeric_seconds, f.analyze_seconds) + f.ordering + ")";
}

// Why the factorization of K_ii failed: the matrix (singular: a part no interface holds), or the
// solver's workspace or memory.
std::string FactorizationFailure(const FactorizationInfo& f) {
  if (f.resource_failure) return "the factorization of K_ii failed: " + f.message;
  return "K_ii (stiffness with all interfaces clamped) is singular: " + f.message +
         "; some part of the model is not held by any interface";
}

// This rank's rows of the interior of the inertia loads f = -M A_k (A: this rank's rows of the
// inertia fields, n x k in all).
Eigen::MatrixXd InertiaLoads(const FeModel& model, const InterfacePartition& p, const Eigen::MatrixXd& fields) {
  const ColumnShare& rows = model.columns;
  const Eigen::MatrixXd MA = SharedTimesRows(model.M, fields, rows);  // this rank's model rows
  const long first = rows.whole() ? 0 : rows.first;
  Eigen::MatrixXd f(p.held_rows(), fields.cols());
  for (long k = 0; k < f.rows(); ++k) f.row(k) = -MA.row(p.interior[size_t(p.held_first() + k)] - first);
  return f;
}

// The lowest `nev` fixed-interface modes: shift-invert around 0 on the factor, on W x = 0, by a
// dense solver for a small interior, the solver's own (SLEPc on MPI ranks) or femb's block
// Lanczos; the vectors are this rank's rows. How they were solved into *how.
EigenResult FixedInterfaceModes(const InterfacePartition& p, const Blocks& K, const Blocks& M, InteriorSolver& factor,
                                const ConstrainedSolver& solver, int nev, long dense_limit, std::string* how) {
  const ColumnShare& held = p.interior_share;
  // (whole vectors in and out: this rank's rows solved, the ranks' gathered)
  const auto whole_solve = [&](const Eigen::MatrixXd& z) { return GatherRows(solver.Solve(HeldRows(z, held)), held); };
  if (p.n_i <= dense_limit || 2 * nev + 1 > p.n_i - p.n_c) {
    const ShiftInvertFn solve = [&](const double* b, double* x) {
      Eigen::Map<const Eigen::VectorXd> bv(b, p.n_i);
      Eigen::Map<Eigen::VectorXd> xv(x, p.n_i);
      xv = whole_solve(Eigen::MatrixXd(bv));
    };
    EigenResult eig = LowestConstrainedEigenpairs(GatherColumns(K.ii, held), GatherColumns(M.ii, held),
                                                  Eigen::MatrixXd(p.Wt.transpose()), nev, 0.0, solve, dense_limit);
    eig.vectors = HeldRows(eig.vectors, held);
    *how = eig.dense ? ", dense solver (small interior)" : ", block shift-invert Lanczos, 0 passes over the factor";
    return eig;
  }
  const auto rows_solve = [&](const Eigen::MatrixXd& z) { return solver.Solve(z); };
  if (std::optional<EigenResult> own = factor.Eigenpairs(K.ii, M.ii, nev, kLanczosTolerance, rows_solve, p.n_c == 0)) {
    *how = ", " + factor.EigenDetail();
    return std::move(*own);
  }
  // (femb's Lanczos multiplies by the whole K_ii and M_ii: one process)
  if (!held.whole()) throw std::logic_error("the block Lanczos on a share of K_ii and M_ii");
  long passes = 0;
  EigenResult eig = BlockLanczosEigenpairs(K.ii, M.ii, Eigen::MatrixXd(p.Wt.transpose()), nev, 0.0, rows_solve,
                                           kLanczosBlock, kLanczosTolerance, &passes);
  *how = Format(", block shift-invert Lanczos, %.0f passes over the factor", double(passes));
  return eig;
}

CraigBamptonResult Reduce(const FeModel& model, FeModel* release, int internal_modes, const ProgressFn& progress,
                          long dense_limit, double memory_limit_bytes, const DerivativeRequest* derivatives,
                          const Eigen::MatrixXd* inertia_fields, ReductionSolver solver_kind) {
  CraigBamptonResult r;
  Stopwatch clock;
  InterfacePartition p;
  if (!PartitionInterfaces(model, p, &r.message)) return r;
  if (internal_modes > p.n_i - p.n_c) {
    r.message = "reduction.internal_modes = " + std::to_string(internal_modes) + " exceeds the " +
                std::to_string(p.n_i - p.n_c) + " interior DOFs of the model";
    return r;
  }
  Blocks K = Partition(model.K, p.interior_index, p.boundary_index, p.n_i, p.n_b);
  Blocks M = Partition(model.M, p.interior_index, p.boundary_index, p.n_i, p.n_b);
  const bool inertia = inertia_fields && inertia_fields->cols() > 0;
  Eigen::MatrixXd inertia_loads = inertia ? InertiaLoads(model, p, *inertia_fields) : Eigen::MatrixXd();
  HeldAsBlocks held(release, K, M, p.interior, p.interior_index);

  // One factorization (METIS ordering, supernodal) of K_ii, or of the augmented F (Augmented).
  // While it lives, the dense blocks (static modes, modes, derivatives, inertia displacements) are
  // each rank's rows of them (on MPI ranks: the factor's own share, not the whole on every rank).
  clock.Restart();
  SparseMatrix F_augmented;
  if (p.n_b == 0) F_augmented = Augmented(K.ii, p.Wt, p.interior_share);
  std::unique_ptr<InteriorSolver> factor = MakeInteriorSolver(solver_kind);
  r.factorization = factor->Factorize(p.n_b == 0 ? F_augmented : K.ii, p.interior_share, memory_limit_bytes);
  const double t_factor = clock.Seconds();
  if (r.factorization.too_big) {
    r.message = r.factorization.message;
    return r;
  }
  if (!r.factorization.ok) {
    r.message = FactorizationFailure(r.factorization);
    return r;
  }
  if (progress) progress("factorize K_ii", t_factor, FactorizationDetail(r.factorization, p.n_i));

  clock.Restart();
  const ConstrainedSolver solver(*factor, p.Wt, p.interior_share);
  Eigen::MatrixXd Psi_b, Psi_c;
  StaticModes(model, p, K.ib, solver, Psi_b, Psi_c);
  if (progress) {
    progress("static modes", clock.Seconds(),
             Format("%.0f constraint modes, %.0f linear solves", p.n_b + p.n_c, double(factor->solves())));
  }

  // Fixed-interface modes; one mode more than kept (when there is one): its frequency tells
  // whether the cut splits equal modes.
  clock.Restart();
  const int nev = internal_modes > 0 && internal_modes + 1 <= p.n_i - p.n_c ? internal_modes + 1 : internal_modes;
  std::string how;
  EigenResult eig = FixedInterfaceModes(p, K, M, *factor, solver, nev, dense_limit, &how);
  if (!eig.ok) {
    r.message = "fixed-interface eigen solve failed: " + eig.message;
    return r;
  }
  if (nev > internal_modes) {
    r.next_lambda = eig.lambda[internal_modes];
    eig.lambda.conservativeResize(internal_modes);
    eig.vectors.conservativeResize(Eigen::NoChange, internal_modes);
  }
  r.lambda = eig.lambda;
  r.eigen_linear_solves = eig.linear_solves;
  r.dense_eigen = eig.dense;
  Eigen::MatrixXd& Phi_i = eig.vectors;
  if (progress) {
    progress("eigen solve", clock.Seconds(),
             Format("%.0f fixed-interface modes, %.0f linear solves (%.1f per mode)", internal_modes,
                    double(eig.linear_solves), double(eig.linear_solves) / std::max(internal_modes, 1)) +
                 how);
  }

  clock.Restart();
  Eigen::MatrixXd Theta(p.held_rows(), 0), inertia_u;
  if (derivatives && !derivatives->pairs.empty()) {
    const Eigen::MatrixXd shapes =
        ShapesOnRows(p, FirstModelRow(model), ModelRows(model), p.held_first(), Psi_b, Psi_c, Phi_i, Eigen::MatrixXd(),
                     6 * int(model.interface_names.size()) + internal_modes);
    Theta = ModalDerivatives(p, M.ii, Phi_i, shapes, FirstModelRow(model), *derivatives, solver, r);
    if (progress) {
      progress(
          "modal derivatives", clock.Seconds(),
          Format("%.0f of %.0f kept (deflation tolerance ", double(Theta.cols()), double(derivatives->pairs.size())) +
              Format("%.1e), %.0f linear solves", derivatives->tolerance, double(derivatives->pairs.size())));
    }
    clock.Restart();
  }
  if (inertia) {
    inertia_u = InertiaDisplacements(p, K.ii, Phi_i, Theta, inertia_loads, solver);
    inertia_loads = Eigen::MatrixXd();
    if (progress) {
      progress("inertia loads", clock.Seconds(),
               Format("%.0f static solves with the interfaces held", double(inertia_fields->cols())));
    }
    clock.Restart();
  }
  // The factor is no longer needed: freed before K and M are rebuilt, then the blocks. The shapes
  // stay each rank's rows: those of the model's columns it holds.
  factor.reset();
  held.Restore();
  K = Blocks(), M = Blocks();
  if (inertia) r.inertia_displacements = FieldsOnModelRows(model, p, inertia_u);
  Project(model,
          ShapesOnRows(p, FirstModelRow(model), ModelRows(model), p.held_first(), Psi_b, Psi_c, Phi_i, Theta,
                       6 * int(model.interface_names.size()) + internal_modes),
          r);
  if (progress) progress("projection", clock.Seconds(), Format("%.0f reduced DOFs", int(r.shapes.cols())));
  r.ok = true;
  return r;
}

}  // namespace

CraigBamptonResult CraigBamptonReduce(const FeModel& model, int internal_modes, const ProgressFn& progress,
                                      long dense_limit, double memory_limit_bytes, const DerivativeRequest* derivatives,
                                      const Eigen::MatrixXd* inertia_fields, ReductionSolver solver_kind) {
  return Reduce(model, nullptr, internal_modes, progress, dense_limit, memory_limit_bytes, derivatives, inertia_fields,
                solver_kind);
}

CraigBamptonResult CraigBamptonReduce(FeModel& model, int internal_modes, const ProgressFn& progress, long dense_limit,
                                      double memory_limit_bytes, const DerivativeRequest* derivatives,
                                      const Eigen::MatrixXd* inertia_fields, ReductionSolver solver_kind) {
  return Reduce(model, &model, internal_modes, progress, dense_limit, memory_limit_bytes, derivatives, inertia_fields,
                solver_kind);
}

}  // namespace femb
