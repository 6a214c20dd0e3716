#include "reducer/reduce_part.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cstdio>
#include <memory>

#include "formats/hdf5_file.h"
#include "formats/input_error.h"
#include "reducer/fe/beam_model.h"
#include "reducer/fe/imported_model.h"
#include "reducer/fe/nonlinear_beam.h"
#include "reducer/fe/nonlinear_solid.h"
#include "reducer/fe/solid_model.h"
#include "reducer/fe/solid_ranks.h"
#include "reducer/linalg/interior_solver.h"
#include "reducer/linalg/shared_columns.h"
#include "reducer/linalg/sparse_cholesky.h"
#include "reducer/part_nonlinear.h"
#include "reducer/reduction/craig_bampton.h"
#include "reducer/reduction/floating_frame.h"
#include "reducer/reduction/full_modes.h"
#include "reducer/reduction/general_basis.h"
#include "reducer/reduction/modal_stress.h"

#ifndef FEMB_VERSION
#define FEMB_VERSION "unknown"
#endif

namespace femb {

namespace {

// Imported parts with geometric stiffening: how far femb's own elements (the part's material on
// the imported mesh) may differ from the imported stiffness, relative on the reduced K. Another
// code's element formulation differs by 1e-6 .. 1e-4 (CalculiX's TET10: 6e-6 in frequency); a
// wrong modulus or Poisson ratio by percent.
constexpr double kImportedStiffnessMismatch = 1e-3;

// The deformation shapes of reduction.method general: a Matrix Market file (ReadShapeMatrix), or
// an HDF5 file (.h5, .hdf5) with the dataset /shapes, one row per DOF and one column per shape
// (h5py: f["shapes"] = V).
Eigen::MatrixXd ReadShapes(const std::string& path, long rows) {
  const size_t dot = path.find_last_of('.');
  const std::string ext = dot == std::string::npos ? "" : path.substr(dot);
  if (ext != ".h5" && ext != ".hdf5") return ReadShapeMatrix(path, rows);
  const h5::Reader r(path);
  if (!r.Exists("/shapes")) throw InputError(path + ": no dataset /shapes (one row per DOF, one column per shape)");
  const std::vector<hsize_t> shape = r.Shape("/shapes");
  if (shape.size() != 2 || long(shape[0]) != rows || shape[1] < 1) {
    std::string got;
    for (hsize_t d : shape) got += (got.empty() ? "" : " x ") + std::to_string(d);
    throw InputError(path + ": /shapes is (" + got + "), expected (" + std::to_string(rows) +
                     " x shapes): one row per DOF, in the matrices' (or the mesh's) order");
  }
  Eigen::MatrixXd V = r.Matrix("/shapes");
  if (!V.allFinite()) throw InputError(path + ": /shapes has a value that is not finite");
  return V;
}

// The FE model of the part: meshed solids, imported matrices or beams. `shared`: on the MPI ranks
// of a distributed reduction, K and M shared by columns (a solid assembles only its share; the
// others keep their share of the whole), checked to be one model on every rank.
FeModel BuildFeModel(const PartSpec& part, const ProgressFn& report, bool shared) {
  FeModel model;
  if (part.type == PartType::kSolid) {
    model = shared ? BuildSolidModelOnRanks(part, report) : BuildSolidModel(part, report);
  } else if (part.type == PartType::kImported) {
    model = BuildImportedModel(part, report);
  } else {
    Stopwatch clock;
    model = BuildBeamModel(part);
    char detail[200];
    std::snprintf(detail, sizeof detail, "%ld nodes, %ld %s elements, %ld DOFs", model.n_nodes(), model.n_elements(),
                  model.element_type.c_str(), model.n_dofs());
    report("mesh+assembly", clock.Seconds(), detail);
  }
  if (!shared) return model;
  if (part.type != PartType::kSolid) CheckSamePartOnRanks(part);  // (a solid's: once it has the mesh)
  if (model.columns.whole()) {
    model.columns = ShareOfColumns(model.n_dofs());
    model.K = KeepColumns(model.K, model.columns);
    model.M = KeepColumns(model.M, model.columns);
  }
  std::vector<double> replicated = {double(model.n_dofs()), double(model.n_nodes()), double(model.n_elements()),
                                    model.nodes.sum(), double(model.cells.sum())};
  for (const Eigen::Vector3d& x : model.interface_positions)
    replicated.insert(replicated.end(), x.data(), x.data() + 3);
  CheckSameOnRanks(replicated, "models");
  return model;
}

// What the factorization may use, from the checks that need only the mesh and the mass.
struct Budget {
  bool keep_mesh = false;
  double dense_bytes = 0.0;   ///< the dense blocks the reduction keeps
  double factor_bytes = 0.0;  ///< what is left for the factor of K_ii (0: no limit known)
  bool limit_given = false;   ///< reduction.memory_limit_gb (else MemAvailable)
};

// Refuses before the factorization and eigen solve what needs only the mesh and the mass: the
// floating frame, stresses without the mesh, more modes than interior DOFs. The memory for the
// factor of K_ii is what is left beside the dense blocks the reduction keeps (constraint modes,
// Lanczos vectors, the mode shapes of the full model).
Budget CheckBeforeFactorization(const PartSpec& part, const FeModel& model) {
  CheckFloatingFrame(part.reduction, model);
  Budget budget;
  budget.keep_mesh = part.reduction.keep_mesh.value_or(model.n_dofs() <= ReductionSpec::kKeepMeshMaxDofs);
  if (!budget.keep_mesh && part.reduction.stresses.value_or(false)) {
    throw InputError(part.reduction.where_stresses +
                     ": reduction.stresses: true needs the mesh, which is not kept for "
                     "more than " +
                     std::to_string(ReductionSpec::kKeepMeshMaxDofs) + " DOFs (this part has " +
                     std::to_string(model.n_dofs()) + "): set reduction.keep_mesh: true");
  }
  const long n_interior = long(InteriorDofs(model).size());
  if (part.reduction.internal_modes > n_interior) {
    throw InputError(part.file + ": reduction.internal_modes = " + std::to_string(part.reduction.internal_modes) +
                     " exceeds the " + std::to_string(n_interior) +
                     " interior DOFs of the mesh (refine it or keep fewer modes)");
  }
  const int n_b = 6 * int(model.interface_names.size()), m = part.reduction.internal_modes;
  budget.dense_bytes = 8.0 * double(model.n_dofs()) * (2.0 * (n_b + m) + 2.0 * m + 20.0);
  budget.limit_given = part.reduction.memory_limit_gb > 0;
  // (MemAvailable is shared by the MPI ranks on this machine that share the work; a given limit is
  // each rank's)
  const int sharing = ResolvedSolver(part.reduction.solver) == ReductionSolver::kPetsc ? RanksOnThisMachine() : 1;
  const double limit =
      budget.limit_given ? part.reduction.memory_limit_gb * 1e9 : AvailableMemoryBytes() / double(std::max(sharing, 1));
  budget.factor_bytes = limit > 0 ? std::max(limit - budget.dense_bytes, 0.1 * limit) : 0.0;
  return budget;
}

// Why femb's own solid elements cannot be put on an imported part's mesh (empty: they can):
// only where every cell is a solid femb knows and every DOF a translation.
std::string WhyNoOwnElements(const FeModel& model) {
  if (!SolidTypeOf(model.cell_type)) return std::string("its mesh has ") + Name(model.cell_type) + " cells";
  for (size_t d = 0; d < model.dof_component.size(); ++d)
    if (model.dof_component[d] >= 3 && model.dof_node[d] < model.n_nodes()) return "its matrices have rotational DOFs";
  return "";
}

// Whether the file gets geometric stiffening: the unit inertia load cases are then solved on
// the same factor as the constraint modes. A basis without deformation (one interface node, no
// internal modes: the six rigid motions) has nothing to stiffen, and its exact and corotational
// kinetic energies are the same. An imported part has it through femb's own Green-Lagrange solid
// elements on its mesh with the part's material.
bool UsesStiffening(const PartSpec& part, const FeModel& model, const ProgressFn& progress) {
  const int n_b = 6 * int(model.interface_names.size()), m = part.reduction.internal_modes;
  bool stiffening = part.reduction.GeometricStiffening(part.type, part.has_material) && n_b + m > 6;
  if (stiffening && part.type == PartType::kImported) {
    std::string why = WhyNoOwnElements(model);
    if (!why.empty()) {
      if (why.find("cells") != std::string::npos) why += " (femb's solid elements: tet4, tet10, hex8, hex20)";
      if (part.reduction.geometric_stiffening.value_or(false)) {
        throw InputError(part.file + ": reduction.geometric_stiffening: the imported part cannot have it: " + why);
      }
      if (progress) progress("stiffening", 0.0, "none: " + why + "; the body is linear inside");
      stiffening = false;
    }
  }
  if (part.reduction.geometric_stiffening.value_or(false) && !stiffening) {
    if (progress)
      progress("stiffening", 0.0,
               "none stored: the basis is the six rigid motions (one interface node, no internal modes)");
  }
  return stiffening;
}

// The message of a reduction refused for memory: how much, and what to do.
std::string TooBigMessage(const Budget& budget, const std::string& message) {
  char why[160];
  std::snprintf(why, sizeof why, " (%s; %.3g GB kept for the dense blocks of the reduction)",
                budget.limit_given ? "reduction.memory_limit_gb" : "MemAvailable", budget.dense_bytes / 1e9);
  return message + why +
         ": coarsen the mesh (mesh.size), use first-order elements (mesh.order: 1), share the factor over more "
         "MPI ranks (mpirun -np N femb-reduce, reduction.solver: petsc), or run on a machine with more memory";
}

// The free-interface basis: the part's lowest free-free modes with the static constraint modes
// (which carry the interface stiffness exactly). Into V with its description; false with
// result.message when the eigen solve fails.
bool FreeInterfaceShapes(const PartSpec& part, const FeModel& model, const CraigBamptonResult& cb, Eigen::MatrixXd& V,
                         std::string& source, ReduceResult& result) {
  const int n_b = 6 * int(model.interface_names.size()), k = part.reduction.internal_modes;
  Eigen::MatrixXd free_modes;
  Eigen::VectorXd free_lambda;
  if (k > 0) {
    const FullModesResult full =
        FullFreeFreeFrequencies(model, k, 1e-8 * LargestDiagonalRatio(model.K, model.M), &free_modes, &free_lambda);
    if (!full.ok) {
      result.message = "free-free eigen solve failed: " + full.message;
      return false;
    }
  }
  V.resize(model.n_dofs(), n_b + k);
  V << cb.shapes.leftCols(n_b), free_modes.rightCols(k);
  std::string freqs;
  for (int j = 6; j < std::min<int>(int(free_lambda.size()), 10); ++j) {
    char b[32];
    std::snprintf(b, sizeof b, "%s%.4g", freqs.empty() ? "" : ", ", FrequencyHz(free_lambda[j]));
    freqs += b;
  }
  source = std::to_string(k) + " free-free modes (" + freqs + (k > 4 ? ", ..." : "") + " Hz) + " + std::to_string(n_b) +
           " static modes";
  return true;
}

// The general basis: the user's shapes on the imported DOFs or the mesh's, fitted to the model
// DOFs by least squares (an RBE2 face moves rigidly in the model, the shapes may not). The
// shapes' rows: the imported matrices' DOFs, or for femb's own parts the mesh's nodes
// (dofs_per_node each, node-major, the order of /visualization/nodes): the RBE2 couplings
// eliminate coupled solid nodes (mesh_map); beam DOFs are the model's own.
Eigen::MatrixXd GeneralShapes(const PartSpec& part, const FeModel& model, std::string& source) {
  SparseMatrix identity(model.n_dofs(), model.n_dofs());
  identity.setIdentity();
  const SparseMatrix& T = model.full_map.size() ? model.full_map : model.mesh_map.size() ? model.mesh_map : identity;
  const Eigen::MatrixXd V_full = ReadShapes(part.reduction.basis_file, T.rows());
  Eigen::SimplicialLDLT<SparseMatrix> normal(SparseMatrix(T.transpose() * T));
  Eigen::MatrixXd V = normal.solve(Eigen::MatrixXd(T.transpose() * V_full));
  const double off_rigid = (Eigen::MatrixXd(T * V) - V_full).norm() / std::max(V_full.norm(), 1e-300);
  char b[96];
  std::snprintf(b, sizeof b, " (%.2g of their norm off the RBE2 faces' rigid motion)", off_rigid);
  source = std::to_string(V.cols()) + " shapes from " + part.reduction.basis_file + b;
  return V;
}

// Thesis 8.2 (reducer/reduction/general_basis.h): replaces cb's basis, K, M and frequencies by
// the free-interface or general basis' and sets the interface constraint (case 4, m < 6N).
// false with result.message on a numerical failure.
bool ReduceOnOtherBasis(const PartSpec& part, const FeModel& model, const ProgressFn& report, CraigBamptonResult& cb,
                        Eigen::MatrixXd& interface_constraint, ReduceResult& result) {
  const bool free_interface = part.reduction.method == ReductionMethod::kFreeInterface;
  const int n_b = 6 * int(model.interface_names.size());
  Stopwatch basis_clock;
  Eigen::MatrixXd V;
  std::string where, source;
  if (free_interface) {
    if (!FreeInterfaceShapes(part, model, cb, V, source, result)) return false;
    where = part.reduction.where_method + ": reduction.method free_interface";
  } else {
    V = GeneralShapes(part, model, source);
    where = part.reduction.where_basis + ": " + part.reduction.basis_file;
  }
  const Eigen::MatrixXd static_modes = cb.shapes.leftCols(n_b);
  const GeneralBasisResult g = ReduceOnGeneralBasis(model, V, &static_modes);
  if (!g.ok) {
    if (g.input_error) throw InputError(where + ": " + g.message);
    result.message = g.message;
    return false;
  }
  cb.K = g.K;
  cb.M = g.M;
  cb.shapes = g.shapes;
  cb.lambda = g.lambda;
  interface_constraint = g.interface_constraint;
  std::string constrained;
  for (size_t i = 0; i < g.constraint_direction.size(); ++i) {
    static const char* kNames[6] = {"u_x", "u_y", "u_z", "theta_x", "theta_y", "theta_z"};
    constrained += i ? "; " : "; constrained inside the body (thesis 8.2 case 4): ";
    for (size_t j = 0; j < g.constraint_direction[i].size(); ++j) {
      const int at = g.constraint_direction[i][j];
      constrained += (j ? " & " : "") + model.interface_names[size_t(at / 6)] + "." + kNames[at % 6];
    }
  }
  char detail[640];
  std::snprintf(detail, sizeof detail,
                "%s: %d of %d shapes with the rigid fields independent, interface rank %d of %d "
                "(thesis 8.2), %ld reduced DOFs",
                source.c_str(), g.columns_kept, g.columns_given + 6, g.interface_rank, n_b, long(g.K.rows()));
  report(free_interface ? "free-interface basis" : "general basis", basis_clock.Seconds(), detail + constrained);
  return true;
}

// A cut inside a group of equal frequencies (within 1e-6: a round or square section, a
// symmetric part) keeps an arbitrary direction of the group: a round coupler with 1 mode kept
// of its pair at 728.342 Hz (the two bending planes) put a four-bar's reactions 30-50% off
// its own converged run, where 2 modes are converged to 2e-4. The warning, or none.
std::optional<std::string> CutGroupWarning(const CraigBamptonResult& cb) {
  if (!(cb.next_lambda > 0 && cb.lambda.size() > 0)) return std::nullopt;
  const double last = cb.lambda[cb.lambda.size() - 1];
  if (cb.next_lambda - last > 1e-6 * cb.next_lambda) return std::nullopt;
  char buffer[400];
  std::snprintf(buffer, sizeof buffer,
                "reduction.internal_modes = %ld keeps mode %ld at %.6g Hz but not mode %ld at the same frequency "
                "(%.6g Hz; a symmetric section or part): the modes kept span an arbitrary direction of that group; "
                "keep the whole group (internal_modes: %ld or more)",
                long(cb.lambda.size()), long(cb.lambda.size()), FrequencyHz(last), long(cb.lambda.size()) + 1,
                FrequencyHz(cb.next_lambda), long(cb.lambda.size()) + 1);
  return std::string(buffer);
}

// The superelement's linear content: interfaces, K and M, frequencies, mass properties, the
// floating frame (with K_r cleaned of its rigid motions' round-off) and the inertia invariants.
void LinearContent(const PartSpec& part, const FeModel& model, const CraigBamptonResult& cb,
                   const Eigen::MatrixXd& interface_constraint, Superelement& se) {
  se.name = part.name;
  se.units = part.units;
  for (size_t k = 0; k < model.interface_names.size(); ++k) {
    se.interfaces.push_back({model.interface_names[k], model.interface_positions[k], Eigen::Matrix3d::Identity()});
  }
  se.K = cb.K;
  se.M = cb.M;
  se.interface_constraint = interface_constraint;
  se.internal_frequencies_hz.resize(cb.lambda.size());
  for (int k = 0; k < cb.lambda.size(); ++k) se.internal_frequencies_hz[k] = FrequencyHz(cb.lambda[k]);
  se.n_full_dofs = model.n_dofs();
  for (const InterfaceSpec& i : part.interfaces) {
    if (part.type != PartType::kBeam && i.coupling == Coupling::kRbe2) se.full_rigid_couplings.push_back(i.name);
  }
  se.n_modal_derivatives = long(cb.derivative_pairs.size());
  se.modal_derivative_pairs = cb.derivative_pairs;
  se.mass_properties = ComputeMassProperties(se);
  se.floating_frame = ComputeFloatingFrame(part.reduction, se, model, cb.shapes);
  // Rigid motions cost no energy exactly: K_r <- T0^T K_r T0 with T0 = 1 - Phi_rig0 Phi_CB
  // (thesis 3.17-3.20 at the undeformed state; T0 Phi_rig0 = 0 as Phi_CB Phi_rig0 = 1). It
  // removes only the round-off of K_r Phi_rig0 = 0 (||K Phi_rig0|| ~ eps ||K_full||), which for a
  // body with one interface and no modes, whose K_r is nothing but that round-off, made stray
  // "rigid-body frequencies" of a fraction of a hertz.
  const Eigen::MatrixXd Phi_rig0 = RigidBodyModes(se, se.floating_frame.origin);
  const Eigen::MatrixXd T0 = Eigen::MatrixXd::Identity(se.K.rows(), se.K.cols()) - Phi_rig0 * se.floating_frame.Phi_CB;
  const Eigen::MatrixXd K_T0 = se.K * T0;
  se.K = T0.transpose() * K_T0;
  se.K = 0.5 * (se.K + se.K.transpose()).eval();
  // The inertia invariants for the exact kinetic energy of the reduced field in the floating
  // frame (SuperelementBody, "Exact inertia"), for every basis and every kind of part: they need
  // only M, the DOFs' vector components and the basis. Without them the solver takes the
  // corotational inertia (thesis 3.22), whose centrifugal load on a spinning part is a fifth too
  // high (a free bar spinning at 200 rad/s: +21.3% stretch with the free-interface basis, +0.43%
  // with the invariants).
  if (se.n_reduced_dofs() > 6) {
    InertiaInvariants(model, cb.shapes, &se.inertia_gamma, &se.inertia_xi);
  }
}

// The reduced internal force on the whole basis (static and internal modes, derivatives): with
// modal derivatives the cubic polynomial of reduced_polynomial.h; for the geometric stiffening
// alone its quadratic part (the geometric stiffness of the stress of each basis vector). Its
// linear part equals K_r. With stiffening also the geometric stiffness of the inertia load cases'
// stresses (InertiaLoads, solver/body/inertia_stiffening.h), about the frame
// origin o: a field about o is the one about the part origin minus the translation it has at o;
// those fields on the model DOFs (this rank's rows on MPI ranks) go to `stress_fields` for their
// stresses. false with result.message when the polynomial's linear part is not K_r.
bool NonlinearForce(const PartSpec& part, const FeModel& model, const CraigBamptonResult& cb, bool stiffening,
                    NonlinearModelOf& nonlinear, const ProgressFn& report, Superelement& se,
                    Eigen::MatrixXd& stress_fields, ReduceResult& result) {
  const bool derivatives = se.n_modal_derivatives > 0;
  Stopwatch tensors;
  PolynomialRequest poly_request;
  poly_request.cubic = derivatives;
  // A solid's interface faces turn to second order (InterfaceRotationCompletion; beams have none),
  // made K-orthogonal to the internal modes and derivatives (CompletionProjection): only the
  // static modes' stress works on it, and the cubic energy stays a square (C (L q + Q z / 2))^2 / 2.
  poly_request.static_coordinates = 6 * int(model.interface_names.size());
  if (stiffening) {
    stress_fields = cb.inertia_displacements;  // (this rank's rows of them on MPI ranks)
    const Eigen::Matrix<double, 3, 12> at_origin = InertiaFieldAt(se.floating_frame.origin);
    for (int k = 3; k < kInertiaLoadCaseCount; ++k)
      stress_fields.col(k) -= stress_fields.leftCols(3) * at_origin.col(k);
  }
  ReducedPolynomial poly;
  if (part.type != PartType::kBeam) {
    // (a solid's element loops on this rank's cells, with the shapes' rows their nodes need)
    const RankMesh& mesh = nonlinear.Mesh();
    const Eigen::MatrixXd mesh_shapes = RankMeshFields(model, mesh, cb.shapes);
    const Eigen::MatrixXd mesh_fields = stiffening ? RankMeshFields(model, mesh, stress_fields) : Eigen::MatrixXd();
    if (stiffening) poly_request.stress_fields = &mesh_fields;
    poly = ReduceSvk(
        nonlinear.OnRankMesh(), mesh_shapes,
        InterfaceRotationCompletion(mesh.nodes, mesh_shapes, model.interface_positions, se.floating_frame.origin),
        poly_request);
  } else {
    const NonlinearModel& beams = nonlinear.Get();
    const SparseMatrix& T = nonlinear.to_model_dofs();  // (the identity, set by Get)
    const Eigen::MatrixXd fields = stiffening ? MappedGatherRows(T, stress_fields, model.columns) : Eigen::MatrixXd();
    if (stiffening) poly_request.stress_fields = &fields;
    poly = ReduceVonKarman(static_cast<const VonKarmanBeams&>(beams), MappedGatherRows(T, cb.shapes, model.columns),
                           poly_request);
  }
  const double mismatch = (poly.K - cb.K).norm() / cb.K.norm();
  if (part.type == PartType::kImported && mismatch > kImportedStiffnessMismatch) {
    // femb's elements with the part's material on the imported mesh must be the imported
    // stiffness (up to element formulation): else their stresses, hence the geometric
    // stiffness, belong to another material or model.
    char text[400];
    std::snprintf(text, sizeof text,
                  "%s: material: femb's elements on the imported mesh with this material differ from the imported "
                  "stiffness by %.2g (reduced K, relative; at most %.0e): give the material the matrices were made "
                  "with, or reduction.geometric_stiffening: false",
                  part.file.c_str(), mismatch, kImportedStiffnessMismatch);
    throw InputError(text);
  }
  if (part.type != PartType::kImported && mismatch > 1e-8) {
    result.message = "the polynomial internal force's linear part differs from K_r by " + std::to_string(mismatch);
    return false;
  }
  se.polynomial = PolynomialStiffness{std::move(poly.A), std::move(poly.B), Eigen::MatrixXd()};
  const long nr = se.K.rows(), P = nr * (nr + 1) / 2;
  if (stiffening) {
    for (int k = 0; k < kInertiaLoadCaseCount; ++k) {
      Eigen::MatrixXd K_sigma(nr, nr);
      int p = 0;
      for (int i = 0; i < nr; ++i)
        for (int j = i; j < nr; ++j, ++p) K_sigma(i, j) = K_sigma(j, i) = poly.S(k, p);
      se.inertia_stiffness.push_back(std::move(K_sigma));
    }
  }
  char detail[640];
  if (derivatives) {
    std::snprintf(detail, sizeof detail,
                  "quadratic %ld x %ld + cubic %ld x %ld coefficients (%.3g MB; symmetric pairs: %.0fx smaller than "
                  "n^3 + n^4), linear part = K_r to %.1e%s",
                  nr, P, P, P, 8.0 * (nr * P + P * P) / 1e6,
                  double(nr * nr * nr + nr * nr * nr * nr) / double(nr * P + P * P), mismatch,
                  stiffening ? "; 12 inertia load case geometric stiffnesses" : "");
    report("nonlinear force", tensors.Seconds(), detail);
  } else {
    std::snprintf(detail, sizeof detail,
                  "quadratic %ld x %ld coefficients (Green-Lagrange over the Craig-Bampton basis) + 12 inertia load "
                  "case geometric stiffnesses %ld x %ld (%.3g MB), linear part = K_r to %.1e",
                  nr, P, nr, nr, 8.0 * (nr * P + 12 * nr * nr) / 1e6, mismatch);
    report("stiffening", tensors.Seconds(), detail);
  }
  return true;
}

// The mesh and the mode shapes on it, for pictures and stresses.
Visualization MeshAndShapes(const FeModel& model, const CraigBamptonResult& cb) {
  Visualization v;
  v.nodes = model.nodes;
  v.cells = model.cells;
  v.cell_type = model.cell_type;
  v.dofs_per_node = model.dofs_per_node;
  // (a solid's on MPI ranks gathered on rank 0 only, which writes the file: the others' stresses
  // take their own rows)
  v.shapes = model.mesh_map.size() ? MappedGatherRows(model.mesh_map, cb.shapes, model.columns, true)
                                   : GatherRows(cb.shapes, model.columns);
  v.interface_nodes = model.interface_node_sets;
  return v;
}

// Whether the file gets modal stresses: with the mesh kept, by default; for imported matrices
// only with femb's solid elements on the imported mesh and the part's material (the same
// conditions as the stiffening's; the part file refuses true without a material).
bool UsesStresses(const PartSpec& part, const FeModel& model, bool keep_mesh) {
  const bool stresses =
      keep_mesh && part.reduction.stresses.value_or(part.type != PartType::kImported || part.has_material);
  if (!stresses || part.type != PartType::kImported) return stresses;
  const std::string why = WhyNoOwnElements(model);
  if (why.empty()) return true;
  if (part.reduction.stresses.value_or(false)) {
    throw InputError(part.file + ": reduction.stresses: the imported part cannot have them: " + why +
                     " (femb's solid elements: tet4, tet10, hex8, hex20)");
  }
  return false;
}

// The modal stresses of the basis on the mesh (reducer/reduction/modal_stress.h) and of the
// inertia load cases' fields. With modal derivatives the stress keeps the strain's quadratic part
// (solids: Green-Lagrange; beams: the von Karman axial term), as the body's polynomial force
// does; the inertia load cases' stresses are linear. On MPI ranks a solid's are each rank's cells',
// gathered on rank 0 (SolidModalStressOnRanks): the others keep none.
void Stresses(const PartSpec& part, const FeModel& model, const CraigBamptonResult& cb,
              const Eigen::MatrixXd& stress_fields, NonlinearModelOf& elements, const ProgressFn& report,
              Superelement& se) {
  Stopwatch stress_clock;
  // (`rows`: fields on the model DOFs, each rank's rows of them on MPI ranks; `on_mesh`: the same on
  // the mesh when at hand)
  const auto stresses_of = [&](const Eigen::MatrixXd& rows, bool quadratic, const Eigen::MatrixXd* on_mesh) {
    if (part.type == PartType::kBeam) return BeamModalStress(part, GatherRows(rows, model.columns), quadratic);
    const SolidType type = SolidCellType(model.cell_type);
    if (!model.columns.whole()) {
      const RankMesh& mesh = elements.Mesh();
      return SolidModalStressOnRanks(type, model.nodes, mesh, part.material, RankMeshFields(model, mesh, rows),
                                     quadratic);
    }
    if (on_mesh) return SolidModalStress(type, model.nodes, model.cells, part.material, *on_mesh, quadratic);
    return SolidModalStress(type, model.nodes, model.cells, part.material, model.mesh_map * rows, quadratic);
  };
  se.stress = stresses_of(cb.shapes, se.n_modal_derivatives > 0, &se.visualization->shapes);
  if (stress_fields.cols() > 0) {
    const ModalStress inertia = stresses_of(stress_fields, false, nullptr);
    se.stress->inertia_modes = inertia.modes;
    se.stress->inertia_section_forces = inertia.section_forces;
  }
  const ModalStress& st = *se.stress;
  char detail[640];
  std::snprintf(detail, sizeof detail, "%d stress points x %ld coordinates (%s%s%s), %.3g MB in single precision",
                st.n_points(), long(cb.shapes.cols()), st.method.c_str(),
                st.gradients.size()           ? "; displacement gradients for the Green-Lagrange quadratic part"
                : st.element_quadratic.size() ? "; element forms of the von Karman axial strain"
                                              : "",
                st.inertia_modes.size() ? "; 12 inertia load cases" : "",
                4.0 *
                    double(st.modes.size() + st.section_forces.size() + st.gradients.size() +
                           st.element_quadratic.size() + st.inertia_modes.size() + st.inertia_section_forces.size()) /
                    1e6);
  report("stresses", stress_clock.Seconds(), detail);
}

}  // namespace

ReduceResult ReducePart(const PartSpec& part, const ProgressFn& progress) {
  ReduceResult result;
  Provenance& prov = result.superelement.provenance;
  const ProgressFn report = [&](const std::string& stage, double seconds, const std::string& detail) {
    prov.stage_seconds.emplace_back(stage, seconds);
    if (progress) progress(stage, seconds, detail);
  };
  const ReductionSolver solver = ResolvedSolver(part.reduction.solver);
  const std::string where_solver = part.reduction.where_solver.empty() ? part.file : part.reduction.where_solver;
  RequireInteriorSolver(solver, where_solver);
  if (solver == ReductionSolver::kPetsc && part.reduction.method != ReductionMethod::kCraigBampton) {
    throw InputError(where_solver +
                     ": reduction.solver: petsc reduces by craig_bampton only (the free-interface and general "
                     "bases are not distributed yet): use solver: cholmod, on one process, with method: " +
                     std::string(Name(part.reduction.method)));
  }
  // (CraigBamptonReduce holds its K and M as blocks for a while)
  FeModel model = BuildFeModel(part, report, solver == ReductionSolver::kPetsc && DistributedRanks() > 1);
  const Budget budget = CheckBeforeFactorization(part, model);
  NonlinearModelOf nonlinear(part, model);
  const DerivativeRequest request = ModalDerivativeRequest(part, model, nonlinear);
  const bool stiffening = UsesStiffening(part, model, progress);
  // (on MPI ranks this rank's rows of them: they live as long as the factor)
  const Eigen::MatrixXd inertia_fields = stiffening ? HeldRows(InertiaFields(model), model.columns) : Eigen::MatrixXd();
  const bool other_basis =
      part.reduction.method == ReductionMethod::kFreeInterface || part.reduction.method == ReductionMethod::kGeneral;
  CraigBamptonResult cb =
      CraigBamptonReduce(model, other_basis ? 0 : part.reduction.internal_modes, report, 200, budget.factor_bytes,
                         request.pairs.empty() ? nullptr : &request, stiffening ? &inertia_fields : nullptr, solver);
  if (!cb.ok) {
    result.too_big = cb.factorization.too_big;
    result.message = result.too_big ? TooBigMessage(budget, cb.message) : cb.message;
    return result;
  }
  Eigen::MatrixXd interface_constraint;  // thesis 8.2 case 4 (m < 6N)
  if (other_basis && !ReduceOnOtherBasis(part, model, report, cb, interface_constraint, result)) return result;

  Stopwatch clock;
  Superelement& se = result.superelement;
  if (std::optional<std::string> warning = CutGroupWarning(cb)) result.warnings.push_back(*warning);
  LinearContent(part, model, cb, interface_constraint, se);
  Eigen::MatrixXd stress_fields;  // the inertia load cases' fields on the model DOFs, with stiffening
  if (stiffening || (nonlinear.built() && se.n_modal_derivatives > 0)) {
    if (!NonlinearForce(part, model, cb, stiffening, nonlinear, report, se, stress_fields, result)) return result;
    clock.Restart();
  }
  if (budget.keep_mesh) se.visualization = MeshAndShapes(model, cb);
  prov.femb_version = FEMB_VERSION;
  prov.input_file = part.file;
  prov.input_hash = part.text_hash;
  prov.element_type = model.element_type;
  prov.reduction_method = Name(part.reduction.method);
  prov.n_nodes = model.n_nodes();
  prov.n_elements = model.n_elements();
  report(
      "frame+mass", clock.Seconds(),
      "floating frame " + se.floating_frame.type +
          (budget.keep_mesh ? ", mesh and mode shapes kept" : ", mesh and mode shapes not kept (reduction.keep_mesh)"));
  if (UsesStresses(part, model, budget.keep_mesh)) Stresses(part, model, cb, stress_fields, nonlinear, report, se);
  if (!FreeFreeCheck(part, model, cb.lambda, progress, report, se, &result.message)) return result;
  result.ok = true;
  return result;
}

}  // namespace femb
