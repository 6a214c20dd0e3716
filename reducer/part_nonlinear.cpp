#include "reducer/part_nonlinear.h"

#include <algorithm>

#include "formats/input_error.h"
#include "reducer/fe/nonlinear_beam.h"
#include "reducer/linalg/shared_columns.h"

namespace femb {

SolidType SolidCellType(CellType cell) {
  if (const std::optional<SolidType> t = SolidTypeOf(cell)) return *t;
  throw InputError(std::string("no solid element type '") + Name(cell) + "'");
}

const NonlinearModel& NonlinearModelOf::Get() {
  if (nonlinear_) return *nonlinear_;
  if (part_.type == PartType::kSolid || part_.type == PartType::kImported) {
    nonlinear_ =
        std::make_unique<SvkSolidMesh>(SolidCellType(model_.cell_type), model_.nodes, model_.cells, part_.material);
  } else {
    nonlinear_ = std::make_unique<VonKarmanBeams>(part_);
    to_model_dofs_.resize(model_.n_dofs(), model_.n_dofs());
    to_model_dofs_.setIdentity();
  }
  return *nonlinear_;
}

const RankMesh& NonlinearModelOf::Mesh() {
  if (!rank_mesh_) rank_mesh_ = std::make_unique<RankMesh>(RankMeshOf(model_));
  return *rank_mesh_;
}

const SvkSolidMesh& NonlinearModelOf::OnRankMesh() {
  const RankMesh& mesh = Mesh();
  if (mesh.share.whole()) return static_cast<const SvkSolidMesh&>(Get());
  if (!rank_solid_) {
    rank_solid_ = std::make_unique<SvkSolidMesh>(SolidCellType(model_.cell_type), mesh.nodes, mesh.cells,
                                                 part_.material, mesh.share);
  }
  return *rank_solid_;
}

namespace {

// The pairs of Craig-Bampton coordinates whose modal derivatives are asked for.
std::vector<std::pair<int, int>> RequestedPairs(const PartSpec& part, int n_interface_dofs, int n_cb) {
  const ModalDerivativeSpec& spec = part.reduction.modal_derivatives;
  if (!spec.pairs.empty()) {
    for (const auto& [i, j] : spec.pairs) {
      if (i >= n_cb || j >= n_cb) {
        throw InputError(spec.where + ".pairs: [" + std::to_string(i) + ", " + std::to_string(j) +
                         "] is not a pair of the " + std::to_string(n_cb) +
                         " Craig-Bampton coordinates (0-based: interfaces' 6 each, then the internal modes)");
      }
    }
    return spec.pairs;
  }
  const int first = spec.of == DerivativePairs::kInternal ? n_interface_dofs : 0;
  const int last = spec.of == DerivativePairs::kStatic ? n_interface_dofs : n_cb;
  std::vector<std::pair<int, int>> pairs;
  for (int i = first; i < last; ++i)
    for (int j = i; j < last; ++j) pairs.emplace_back(i, j);
  return pairs;
}

// 2 f2(a0, b0) by the polarization identity (ModalDerivativeRequest) from `force`, the internal
// force, at a0 and b0 scaled to 1e-6 of the part `size` (by their largest entries a_max, b_max).
template <class Force>
Eigen::VectorXd TwiceBilinearForce(const Force& force, const Eigen::VectorXd& a0, const Eigen::VectorXd& b0,
                                   double a_max, double b_max, double size) {
  const double sa = 1e-6 * size / std::max(a_max, 1e-300), sb = 1e-6 * size / std::max(b_max, 1e-300);
  const Eigen::VectorXd a = sa * a0, b = sb * b0;
  const Eigen::VectorXd f2 = ((force(a + b) - force(a - b)) - (force(b - a) - force(-a - b))) / 8;
  return 2 * f2 / (sa * sb);
}

// A solid's (dK/dq_j) phi_i (ModalDerivativeRequest) on this rank's rows of the model DOFs, given
// its rows of the shapes: its own cells' forces on their nodes (the shapes' rows they need
// fetched), mapped to the model DOFs and added on the ranks that hold them; the scales from the
// largest entries over all ranks, as on one process.
Eigen::MatrixXd SolidDerivativeLoads(const FeModel& model, NonlinearModelOf& nonlinear, double size,
                                     const Eigen::MatrixXd& shapes, const std::vector<std::pair<int, int>>& pairs) {
  const RankMesh& mesh = nonlinear.Mesh();
  const SvkSolidMesh& f = nonlinear.OnRankMesh();
  const Eigen::MatrixXd mesh_shapes = RankMeshFields(model, mesh, shapes);
  // (a rank without cells has no entries: zeros, which the others' exceed)
  Eigen::VectorXd largest = Eigen::VectorXd::Zero(mesh_shapes.cols());
  if (mesh_shapes.rows() > 0) largest = mesh_shapes.cwiseAbs().colwise().maxCoeff().transpose();
  MaxOverRanks(largest);
  Eigen::MatrixXd forces(mesh_shapes.rows(), long(pairs.size()));
  const auto force = [&f](const Eigen::VectorXd& u) { return f.OwnForce(u); };
  for (size_t k = 0; k < pairs.size(); ++k) {
    const auto [i, j] = pairs[k];
    forces.col(long(k)) =
        TwiceBilinearForce(force, mesh_shapes.col(i), mesh_shapes.col(j), largest[i], largest[j], size);
  }
  if (model.columns.whole()) {
    Eigen::MatrixXd out(model.n_dofs(), forces.cols());
    for (long k = 0; k < forces.cols(); ++k) out.col(k) = model.mesh_map.transpose() * forces.col(k);
    return out;
  }
  std::vector<int> rows = mesh.model_rows;
  Eigen::MatrixXd loads = mesh.map.transpose() * forces;
  AddOnOwners(rows, loads, 1, mesh.row_owner);
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(model.columns.count, forces.cols());
  for (size_t r = 0; r < rows.size(); ++r) out.row(rows[r] - model.columns.first) = loads.row(long(r));
  return out;
}

}  // namespace

// Modal derivatives: (dK/dq_j) phi_i = 2 f2(phi_i, phi_j), the symmetric bilinear part of the
// cubic internal force f(u) = K u + f2(u, u) + f3(u, u, u) of the nonlinear model (solids:
// Green-Lagrange; beams: moderate rotation), by the exact polarization identity
// 8 f2(a, b) = [f(a + b) - f(a - b)] - [f(b - a) - f(-a - b)] (the linear and cubic terms
// cancel), evaluated at displacements scaled to 1e-6 of the part size (round-off ~1e-10).
// No pairs when the part asks for none. The request refers to `nonlinear` and `model`.
DerivativeRequest ModalDerivativeRequest(const PartSpec& part, const FeModel& model, NonlinearModelOf& nonlinear) {
  DerivativeRequest request;
  if (!part.reduction.modal_derivatives.enabled) return request;
  const int n_b = 6 * int(model.interface_names.size());
  request.pairs = RequestedPairs(part, n_b, n_b + part.reduction.internal_modes);
  request.tolerance = part.reduction.modal_derivatives.tolerance;
  // (a solid's on MPI ranks on the rank's own cells: SolidDerivativeLoads)
  if (part.type == PartType::kBeam || model.columns.whole()) {
    nonlinear.Get();
  } else {
    nonlinear.OnRankMesh();
  }
  const double size = (model.nodes.colwise().maxCoeff() - model.nodes.colwise().minCoeff()).norm();
  request.stiffness_derivative = [&part, &model, &nonlinear, size](const Eigen::MatrixXd& shapes,
                                                                   const std::vector<std::pair<int, int>>& pairs) {
    if (part.type != PartType::kBeam) return SolidDerivativeLoads(model, nonlinear, size, shapes, pairs);
    // (a beam's whole on every rank)
    const Eigen::MatrixXd whole = GatherRows(shapes, model.columns);
    const NonlinearModel& f = nonlinear.Get();
    const auto force = [&f](const Eigen::VectorXd& u) { return f.Force(u); };
    Eigen::MatrixXd out(model.n_dofs(), long(pairs.size()));
    for (size_t k = 0; k < pairs.size(); ++k) {
      const auto [i, j] = pairs[k];
      out.col(long(k)) = TwiceBilinearForce(force, whole.col(i), whole.col(j), whole.col(i).cwiseAbs().maxCoeff(),
                                            whole.col(j).cwiseAbs().maxCoeff(), size);
    }
    return HeldRows(out, model.columns);
  };
  return request;
}

}  // namespace femb
