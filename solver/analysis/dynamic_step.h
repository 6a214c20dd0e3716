// Internal to the dynamic analysis: what the two integrators (solver/integrators/:
// generalized_alpha.cpp, midpoint.cpp) and the analysis driver (dynamic_analysis.cpp) share, the
// assembly of one pass over the bodies and the kept iteration matrix. Not an interface for
// other code.
//
// Storage: a step of either integrator allocates nothing once the first steps have
// sized everything (tests/solver/analysis/allocation_free_test.cpp counts it). Everything a step or an iteration needs
// lives in the BodyWorkspace (the midpoint scheme's in its MidpointWorkspace; the system-level functions' scratch in
// its parts, SystemScratch), in each body's BodyData (its scratch), and is written in place: no Eigen object
// returned by value, no product of dynamic-size blocks assigned without noalias() or a fixed-size
// holder, no std::function built per call (BodyTask), no std::optional reset that frees.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <Eigen/SparseLU>
#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "solver/analysis/dynamic_analysis.h"
#include "solver/assembly/body_pass.h"
#include "solver/assembly/system.h"
#include "solver/parallel.h"

namespace femb::dynamic_internal {

// Newton's convergence test on an assembly's residual (weighted norm r_norm, FreeNorm): at the
// round-off of the positions, or below `tolerance` relative to the forces on each unknown
// (ScaledFreeNorm with the assembly's dof_scale).
inline bool ResidualSmall(const DofMap& dofs, const Assembly& a, const Eigen::VectorXd& weights, double r_norm,
                          double tolerance) {
  return r_norm <= a.roundoff || ScaledFreeNorm(dofs, a.residual, weights, a.dof_scale) <= tolerance;
}

// One body's share of a step's measures (energies, momenta).
struct BodyMeasure {
  double kinetic = 0.0, elastic = 0.0;
  Eigen::Vector3d linear = Eigen::Vector3d::Zero(), angular = Eigen::Vector3d::Zero();
};

// Nodes whose coordinates include their own spatial rotation increment (free node, spherical
// joint to ground, spherical child): the first index of the rotation triple, and of the
// translation triple when the node is free (-1 otherwise).
struct RotationNode {
  int node, rotation, translation;
};

// (ApplyIncrement composes their rotation increments, R <- exp(d~) R; every other unknown adds.)
std::vector<RotationNode> RotationNodes(const SystemModel& model, const DofMap& dofs);

// A map of Newton's increment delta of the midpoint scheme (MidpointKinematics::T, V), as a
// matrix over the unknowns: the identity times `diagonal` but on the rotation nodes
// (RotationNodes), whose rotation triple maps onto itself by a 3 x 3 block and a free node's
// translation triple onto itself and onto the node's rotation triple. Kept as its blocks (per
// rotation node) and applied to triplets (AddTimesColumns): no sparse matrix is built.
struct StepColumnMap {
  double diagonal = 0.0;
  std::vector<Eigen::Matrix3d> rotation, translation, coupling;  // (r, r), (t, t), (t, r) per rotation node
};

// The unknowns' places in a StepColumnMap's blocks (MidpointWorkspace::triple_of), and the
// StepColumnMap products of the midpoint iteration matrix (solver/integrators/midpoint_columns.cpp).
void TripleOf(const DofMap& dofs, const std::vector<RotationNode>& nodes, std::vector<int>& triple_of);
/// out += scale * A X for the matrix A of the triplets `in`.
void AddTimesColumns(const Triplets& in, double scale, const StepColumnMap& X, const std::vector<RotationNode>& nodes,
                     const std::vector<int>& triple_of, Triplets& out);

// The midpoint scheme's kinematics of one iteration (solver/integrators/midpoint.cpp): the step's
// increment Delta of the coordinates (spatial rotation vectors log(R_n+1 R_n^T) on the rotation
// triples), the end velocities it implies, the mid configuration, and the first-order maps of the
// end coordinates' increments (delta, as Newton applies them at n+1) to the mid configuration and
// to the end velocities.
struct MidpointKinematics {
  Eigen::VectorXd delta;                               // Delta
  Eigen::VectorXd W1;                                  // W_n+1 from the kinematics
  Eigen::VectorXd half;                                // the increment from q_n to q_m
  SystemState mid;                                     // q_m
  StepColumnMap T;                                     // d q_m / d delta: 1/2 off the rotation nodes
  StepColumnMap V;                                     // d W_n+1 / d delta: 2/h off the rotation nodes
  std::vector<Eigen::Matrix<double, 6, 1>> node_w1;    // every node's velocity at n+1 (EndNodeVelocity)
  std::vector<Eigen::Matrix<double, 6, 1>> node_step;  // every node's (x_n+1 - x_n, log(R_n+1 R_n^T))
  std::vector<char> screw_mid;  // per node: its mid position moved for the energy closure (set per model)
};

/// out += B^T (K B T' + M B V' / h) for a body's K and M (local) and map B on the rotation nodes'
/// triples (midpoint_columns.cpp).
void AddRotationColumns(const std::vector<MapEntry>& map, const Eigen::MatrixXd& K, const Eigen::MatrixXd& M, double h,
                        const MidpointKinematics& k, const std::vector<RotationNode>& nodes,
                        const std::vector<int>& triple_of, Triplets& out);

// One body's storage in a midpoint step (its data at q_n+1 is the BodyWorkspace's pass).
struct MidpointBody {
  BodyData d0, dm;                                 // at q_n (once per step) and at q_m
  Eigen::Vector3d com0 = Eigen::Vector3d::Zero();  // the centre of mass at q_n
  Eigen::VectorXd w0, p0, p1, p_mean, wm, w_first, w_second, dw, wdot, s_first, s_second, u, Du;
  Eigen::VectorXd rigid;  // a rigid velocity of the body's nodes (KeepMomenta)
  Eigen::MatrixXd d_w, d_p;
  Eigen::MatrixXd S_b;  // the body's combined iteration matrix (MidpointMatrix)
  BodyData side;        // the exact inertia: MomentumConfigurationTangent's perturbed data
  InertiaLoadFactors load;
  // The energy closure (midpoint_energy.cpp): the energy at q_n, the mismatch, whether there is a closure this
  // iteration and whether its derivative dc is current; the inertia and elastic forces it closes, its direction per
  // unit mismatch, the local force at q_n; the end strain's tangent K_end, and scratch.
  double E0 = 0.0, mismatch = 0.0;
  bool closure_on = false, dc_fresh = false;
  Eigen::VectorXd F, closure, u_local, v, Wv, Q0, base;
  Eigen::MatrixXd dc, Kq, KB, K_end;
};

struct BodyWorkspace;

// The midpoint scheme's storage, kept from one iteration and one step to the next.
struct MidpointWorkspace {
  std::vector<MidpointBody> bodies;
  BodyDataAtState mid_data;  // &bodies[b].dm, for the bodies' interface constraints at q_m
  MidpointKinematics k;
  // Set once for the model: per body, whether it has a free node; the model's size squared.
  std::vector<char> free_node;
  std::vector<char> closes;                        // per body: whether its energy is closed (ClosesEnergy)
  std::shared_ptr<BodyWorkspace> closure_scratch;  // EnergyClosureGradient's differences
  DynamicState closure_state;
  double L2 = 0.0;
  std::vector<double> gravity_work;  // per body
  // Per unknown: 2 i for the rotation triple of rotation node i, 2 i + 1 for its translation
  // triple, -1 elsewhere (StepColumnMap's blocks).
  std::vector<int> triple_of;
  Eigen::VectorXd rates, D, Dd, unused, end;
  NodeForces loads;
  Triplets S, loop_mid, loop_end;  // the iteration matrix's triplets
  TripletAssembler S_build;
  // The free systems (FindFreeSystems, set once for the model): per node its system or -1, per
  // system its reference node; per system the locked inertia and the leftover's impulse of a step.
  std::vector<int> system_of, system_origin;
  std::vector<Eigen::Matrix<double, 6, 6>> locked;
  std::vector<Eigen::Matrix<double, 6, 1>> leftover;
};

// Clears the energy closures' derivatives when it goes out of scope, unless `keep` is set: every
// way out of a step but a fast convergence (failures and exceptions too) leaves them to be
// computed anew.
struct ClosureKeeping {
  MidpointWorkspace& mw;
  bool keep = false;
  ~ClosureKeeping() {
    if (!keep) {
      for (MidpointBody& m : mw.bodies) m.dc_fresh = false;
    }
  }
};

// A square linear system of the Radau IIA step (its iteration matrix, its error filter): entries
// added, factored, solved; held dense or sparse (Start), its storage kept from step to step.
struct RadauLinearSystem {
  bool dense = true;
  Eigen::MatrixXd D;
  Eigen::PartialPivLU<Eigen::MatrixXd> D_lu;
  Triplets triplets;
  Eigen::SparseMatrix<double> S;
  Eigen::SparseLU<Eigen::SparseMatrix<double>> S_lu;
  int n = 0;
  void Start(int size, bool as_dense) {
    n = size;
    dense = as_dense;
    if (dense) D.setZero(n, n);
    triplets.clear();
  }
  void Add(int row, int col, double value) {
    if (dense) {
      D(row, col) += value;
    } else {
      triplets.emplace_back(row, col, value);
    }
  }
  /// False when singular: dense, a pivot below 1e-15 of the largest (Eigen's rcond allocates);
  /// sparse, SparseLU's failure (its pattern analysed at every factorization: the bodies'
  /// matrices leave out their zero entries, so the pattern may change from step to step).
  bool Factor() {
    if (dense) {
      D_lu.compute(D);
      const auto pivots = D_lu.matrixLU().diagonal().cwiseAbs();
      return pivots.minCoeff() > 1e-15 * pivots.maxCoeff();
    }
    S.resize(n, n);
    S.setFromTriplets(triplets.begin(), triplets.end());
    S.makeCompressed();
    S_lu.analyzePattern(S);
    S_lu.factorize(S);
    return S_lu.info() == Eigen::Success;
  }
  void Solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) const {
    if (dense) {
      x = D_lu.solve(b);
    } else {
      x = S_lu.solve(b);
    }
  }
};

// The Radau IIA step's storage (solver/integrators/radau.cpp), kept from one step to the next:
// the stages' states, accelerations, velocities and local coordinates, their residuals, and the
// factored iteration matrix over the stages' solved unknowns.
struct RadauWorkspace {
  std::array<DynamicState, 3> stage;
  std::array<Eigen::VectorXd, 3> A, V, theta;
  std::array<Assembly, 3> assembly;
  std::array<TripletAssembler, 3> K_build, C_build, M_build;  // each stage's (AddDynamicMatrices)
  Eigen::VectorXd rhs, correction, f_drive;
  std::vector<FrameSolution> frames;  // a stage's bodies' frames, kept across its placement
  std::vector<int> position;          // per unknown: its place among the solved ones (-1: prescribed)
  // The iteration matrix: dense up to kDenseStages unknowns (a dense LU of that size costs less
  // than the sparse one's analysis), sparse above.
  static constexpr int kDenseStages = 240;
  RadauLinearSystem J;
  bool factored = false;
  double factored_h = -1.0;
  // Error-controlled steps: the step's local error estimate of the positions and of the
  // velocities times the step (RadauLocalError), and the filter's matrix.
  Eigen::VectorXd error_q, error_v, d, filter_rhs, filtered, product;
  RadauLinearSystem filter;
};

// The bodies' storage of a dynamic analysis, kept from one Newton iteration and one step to the
// next so that evaluating a body reuses its matrices instead of allocating them.
struct BodyWorkspace {
  std::vector<BodyPass> passes;  // the last residual pass; after a converged step, at its state
  BodyDataAtState pass_data;     // &passes[b].data, for the bodies' interface constraints
  std::vector<BodyTerms> terms;  // the last residual pass's; their maps serve the matrix pass too
  struct BodyMatrices {
    Eigen::MatrixXd K, C, M;
    Eigen::MatrixXd d_load, inertia_K;  // scratch (storage kept)
    BodyVelocity wdot;
    Eigen::VectorXd unused;
    // The last computed matrices kept in the body's floating frame, Rbar^T X Rbar (the inertia
    // force's mass and gyroscopic matrices; with BodyMatricesKept::kAll the whole M, C and K),
    // and how many matrix passes since have turned them instead (AddDynamicMatrices, `every`);
    // -1: none kept.
    Eigen::MatrixXd M_frame, C_frame, K_frame;
    int age = -1;
  };
  std::vector<BodyMatrices> matrices;               // the last matrix pass
  long matrices_computed = 0, matrices_turned = 0;  // body matrix passes of each kind, all bodies
  std::vector<BodyMeasure> measures;                // the step's measures, per body
  Triplets K, C, M;                                 // its system triplets (cleared, capacity kept)
  TripletAssembler K_build, C_build, M_build;       // their sparse matrices (slots kept)
  // The system-level storage of an assembly and of a step, kept so that neither allocates.
  AssemblyParts parts;
  Assembly assembly;
  std::vector<Eigen::Matrix<double, 6, 1>> node_acc;
  std::vector<NodeJacobian> dc, dacc;
  Eigen::VectorXd unused, column, weights, dq, delta, lie_delta, a_n, W_n, velocity_change;
  // The factor of the mass in the step's iteration matrix (RoundOffForce; 0 outside a step).
  double inertia_factor = 0.0;
  // RotationNodes(model, dofs), set with the weights.
  std::vector<RotationNode> rotation_triples;
  MidpointWorkspace midpoint;  // the midpoint scheme's own (its passes are the ones above)
  RadauWorkspace radau;        // the Radau IIA step's own (its passes are the ones above)
  // ResidualWeights(model, dofs), computed on the first call (they depend on the model only).
  const Eigen::VectorXd& Weights(const SystemModel& model, const DofMap& dofs) {
    if (weights.size() != dofs.n_dofs()) {
      weights = ResidualWeights(model, dofs);
      rotation_triples = RotationNodes(model, dofs);
    }
    return weights;
  }
};

// The energy closure of a flexible body under the midpoint scheme (midpoint_energy.cpp): which
// bodies take it (two nodes or more, all free and unprescribed, no inertia stiffening, no interface
// constraint, the exact kinematics and quadratic velocity terms); its elastic force, the two
// ends' local forces averaged through the map at q_m; the closure added to that force f_int (m.F
// holds the inertia force without damping on entry); and the closure's derivative over the
// body's coordinates for Newton's matrix (into m.dc), by one-sided differences of the body's
// terms about the end state s1 of the residual pass just made (a scratch workspace of its own).
bool ClosesEnergy(const SystemModel& model, const DofMap& dofs, int b);
// A free node's mid position moved where its step (Delta_x, Delta_pi) is a rigid motion's (into
// `half`, the increment from q_n to q_m), with the maps of the end increments onto it.
void ScrewMidShift(const Eigen::Vector3d& dpi, const Eigen::Vector3d& dx, const Eigen::Matrix3d& Jinv,
                   Eigen::Ref<Eigen::Vector3d> half, Eigen::Matrix3d& T_translation, Eigen::Matrix3d& T_coupling);
void AveragedElasticForce(const SuperelementBody& body, BodyData& d1, MidpointBody& m, Eigen::VectorXd& f_int);
void AveragedElasticTangent(const SuperelementBody& body, BodyData& d1, MidpointBody& m, Eigen::MatrixXd& K_mid,
                            Eigen::MatrixXd& K_end);
void CloseEnergy(const SuperelementBody& body, double h, BodyData& d1, const Eigen::VectorXd& w1, MidpointBody& m,
                 Eigen::VectorXd& f_int);
void EnergyClosureGradient(const SystemModel& model, const DofMap& dofs, const DynamicState& s0, double h,
                           const DynamicState& s1, int b, BodyWorkspace& work);
// The momenta of each free system kept through Newton's leftover (midpoint_momentum.cpp): which
// nodes move together under a rigid motion of a system held by nothing (FindFreeSystems, into
// mw); and, at a converged step whose residual is r, the rigid velocity increment of each such
// system that gives its momenta the impulse h G_m^T r the leftover withheld and what the bodies'
// terms hold against their identities at round-off (KeepMomenta: into next's velocities, the
// node velocities and the passes' body velocities).
void FindFreeSystems(const SystemModel& model, const DofMap& dofs, MidpointWorkspace& mw);
void KeepMomenta(const SystemModel& model, const DofMap& dofs, double h, const Eigen::VectorXd& r, BodyWorkspace& work,
                 DynamicState& next);
// The midpoint step's kinematics at the end state s1 (sets s1's end velocities), into k; one
// body's terms of its balance (BodyTerms) into work (midpoint.cpp).
void Midpoint(const SystemModel& model, const DofMap& dofs, const std::vector<RotationNode>& nodes,
              const DynamicState& s0, double h, DynamicState& s1, MidpointKinematics& k);
void MidpointBodyTerms(const SystemModel& model, const DofMap& dofs, const DynamicState& s0, double h, DynamicState& s1,
                       int b, BodyWorkspace& work);

// The generalized-alpha residual at state s and time t: frames solved (s.config.frames
// updated), each body's kinematics evaluated once and kept in the workspace's passes for the
// matrices, which an iteration builds only when it needs them (not on the converged one, not
// with a kept factorization). Bodies on `threads` threads; the result does not depend on their
// number.
// Into `out` (its storage reused: no allocation once the workspace has its sizes).
void AssembleDynamicResidual(const SystemModel& model, const DofMap& dofs, DynamicState& s, double t,
                             BodyWorkspace& work, BodyThreads* threads, Assembly& out);
Assembly AssembleDynamicResidual(const SystemModel& model, const DofMap& dofs, DynamicState& s, double t,
                                 BodyWorkspace& work, BodyThreads* threads = nullptr);

// Coefficients of an iteration matrix K + c_C C + c_M M (generalized-alpha: gamma', beta').
struct MatrixCombination {
  double c_C = 0.0, c_M = 0.0;
};

// The matrices K, C, M of the residual pass `out` (same state s and time t: K = -dr/dq, C =
// -dr/dW, M = -dr/dWdot); bodies on `threads` threads, added in body order. With `combine`,
// out.K receives the iteration matrix K + c_C C + c_M M alone, combined body by body before the
// scatter (one sparse matrix built instead of three and their sum), and out.C, out.M stay empty.
// every > 1 (Newton's iteration matrix only, DynamicOptions::body_matrices_every): a body whose
// matrices were computed fewer than `every` passes ago takes them turned with its floating
// frame, Rbar X_frame Rbar^T, instead of computing them: its inertia matrices (mass, gyroscopic)
// alone with `which` kInertia (everything else computed every time), all of them with kAll; 1:
// all computed at s.
void AddDynamicMatrices(const SystemModel& model, const DofMap& dofs, const DynamicState& s, double t,
                        BodyWorkspace& work, bool full_inertia_tangent, Assembly& out, BodyThreads* threads = nullptr,
                        const MatrixCombination* combine = nullptr, int every = 1,
                        BodyMatricesKept which = BodyMatricesKept::kAll);

// Residual and (with `matrices`) K, C, M at s, with a workspace of its own.
Assembly AssembleDynamic(const SystemModel& model, const DofMap& dofs, DynamicState& s, double t, bool matrices,
                         bool full_inertia_tangent = false);

// The generalized forces the prescribed motions exert: minus the residual on the prescribed
// coordinates (zero elsewhere).
Eigen::VectorXd DriveForces(const DofMap& dofs, const Eigen::VectorXd& residual);
void DriveForces(const DofMap& dofs, const Eigen::VectorXd& residual, Eigen::VectorXd& f);

// The factorized iteration matrix, kept across iterations (and steps) as JacobianReuseOf(options)
// says.
//
// Within a step (kStep, generalized-alpha's default): the first iteration factors the matrix at
// the predictor; the later ones keep it while every iteration contracts the residual norm at
// least tenfold (kReuseContraction), and factor anew at the current iterate otherwise. This is
// modified Newton within the step, as Adams' default Jacobian pattern (T:F:F:F) and the BDF
// codes (Brenan, Campbell & Petzold 1996, 5.2) do: the residual stays exact, so the converged
// state is the same to the Newton tolerance, and the later iterations, whose corrections are
// small, skip the matrices and the factorization (an iteration's larger part: on the 2 stiffened
// slider-crank bodies at h = 100 us the matrices cost 3x the residual). Measured there: 1.86 ->
// 1.93 iterations and 1.86 -> 1.00 factorizations per step, 0.31 -> 0.22 s, the same error;
// contraction thresholds from 0.03 to 1 gave the same times. With 0.1, an iteration that
// contracts less (a strongly nonlinear step) returns to full Newton at once.
// Across steps (kSteps) the factor is kept while Newton converges within reuse_max_iterations:
// the matrices turn with the bodies, and at this code's tight default tolerance that costs many
// more iterations (the same slider-crank: 7.0 per step against 1.9), so it is an option only.
struct IterationMatrix {
  static constexpr double kReuseContraction = 0.1;
  FreeSolver solver;
  double factored_h = -1.0;
  int with_this_factor = 0;
  long factorizations = 0;
  bool factored_in_step = false;  ///< kStep: the factor is this step's
  double last_residual = -1.0;    ///< the previous iteration's residual norm in this step (-1: none)

  // At the start of every step (and of every retry with a cut step).
  void BeginStep() {
    factored_in_step = false;
    last_residual = -1.0;
  }

  // Factors S() (a callable returning the matrix) unless the kept factor may be reused at this
  // iteration, whose residual norm is r_norm; false when S is singular.
  template <class MatrixOf>
  bool Update(const DofMap& dofs, const DynamicOptions& options, double h, double r_norm, const MatrixOf& S) {
    const bool contracted = last_residual >= 0.0 && r_norm <= kReuseContraction * last_residual;
    last_residual = r_norm;
    bool reuse = false;
    switch (JacobianReuseOf(options)) {
      case JacobianReuse::kNone:
        break;
      case JacobianReuse::kStep:
        reuse = solver.valid() && factored_in_step && contracted;
        break;
      case JacobianReuse::kSteps:
        reuse = solver.valid() && factored_h == h && with_this_factor < options.reuse_max_iterations;
        break;
    }
    if (reuse) {
      ++with_this_factor;
      return true;
    }
    if (!solver.Factor(dofs, S())) return false;
    factored_h = h;
    with_this_factor = 1;
    factored_in_step = true;
    ++factorizations;
    return true;
  }

  // Newton's increment S^-1 r with the kept or a new factor (r_norm: the norm of r the
  // convergence test used). False when S is singular or the increment is not finite; S is then
  // in `singular`.
  template <class MatrixOf>
  bool Increment(const DofMap& dofs, const DynamicOptions& options, double h, double r_norm, const MatrixOf& S,
                 const Eigen::VectorXd& r, Eigen::VectorXd& delta, std::unique_ptr<SystemMatrix>& singular) {
    if (Update(dofs, options, h, r_norm, S)) {
      solver.Solve(r, delta);
      if (delta.allFinite()) return true;
    }
    singular = std::make_unique<SystemMatrix>(S());
    return false;
  }
};

// Newton's divergence test within a step: a residual above the first one (the predictor's).
// Newton that wanders there may still come back and converge, but to whichever root of the
// step's nonlinear equations it meets: a cantilever folding in 3 bodies (examples/
// cantilever_transient, left-node frames, h = 0.5 ms) took residual excursions of 30x, landed
// on a root that raised the energy by 5 J in one step, and which root it was depended on the
// round-off of the linear solver. The step is cut instead (the caller halves it).
// With closed loops the reference is the first iterate whose loops are closed (`closed`): a
// predictor that opens them (a drive accelerating from the start moves its joint, the loop's
// other links do not follow) has a residual that the first correction, closing the loop, may
// double before Newton converges; measured on a rigid four-bar whose crank starts at
// -1000 rad/s^2: every step from 100 us down to 12.5 us was cut at t = 0.
struct DivergenceTest {
  double first = 0.0;
  bool has_first = false;
  bool Diverged(double r, bool closed = true) {
    if (!has_first) {
      if (closed) first = r, has_first = true;
      return false;
    }
    return r > first;
  }
};

struct StepOutcome {
  bool converged = false;
  int iterations = 0;
  /// The iteration matrix when its factorization failed (empty otherwise; a pointer, since an
  /// empty sparse matrix allocates on construction and a step allocates nothing).
  std::unique_ptr<SystemMatrix> singular_matrix;
  bool passes_kept = false;  ///< the workspace's passes hold the bodies' data at the converged state
  /// The integrator's own estimate of the step's local error (Radau IIA under error control), over
  /// the coordinates: of the positions, and of the velocities times the step (null: the step
  /// controller estimates it from the accelerations, StepController::Error).
  const Eigen::VectorXd* error_q = nullptr;
  const Eigen::VectorXd* error_v = nullptr;
};

// The velocities of body b's coordinates: the midpoint scheme's node velocities where the state
// carries them (DynamicState::node_w), J(q) W otherwise.
Eigen::VectorXd BodyVelocityOf(const SystemModel& model, const DofMap& dofs, const DynamicState& s, int b);
void BodyVelocityOf(const SystemModel& model, const DofMap& dofs, const DynamicState& s, int b, Eigen::VectorXd& w);

// One generalized-alpha step of size h from `state` into `next` (solver/integrators/
// generalized_alpha.cpp). t_new: the time reached, state.t + h, or just below a breakpoint the
// step lands on (the loads and drives there are their left limits).
StepOutcome GeneralizedAlphaStep(const SystemModel& model, const DofMap& dofs, const DynamicOptions& options,
                                 const DynamicState& state, double h, double t_new, IterationMatrix& matrix,
                                 BodyThreads& threads, BodyWorkspace& work, DynamicState& next);

// One step of the momentum-conserving midpoint scheme (solver/integrators/midpoint.cpp) of size h from `state`
// into `next`; t_new as for the generalized-alpha step.
// The midpoint scheme's residual (applied minus inertia and internal forces) at the end state s1
// of a step of h from s0, with s1's kinematics made from the step (its end velocities set), as
// MidpointStep assembles it; and its iteration matrix -d(residual)/d(delta), delta the increment
// Newton applies at n+1 (ApplyIncrement). For the tests of the matrix against differences of
// the residual; the results live in `work`.
const Assembly& MidpointResidual(const SystemModel& model, const DofMap& dofs, const DynamicState& s0, double h,
                                 DynamicState& s1, BodyWorkspace& work);
const SystemMatrix& MidpointIterationMatrix(const SystemModel& model, const DofMap& dofs, const DynamicState& s0,
                                            double h, DynamicState& s1, BodyWorkspace& work);

StepOutcome MidpointStep(const SystemModel& model, const DofMap& dofs, const DynamicOptions& options,
                         const DynamicState& state, double h, double t_new, IterationMatrix& matrix,
                         BodyThreads& threads, BodyWorkspace& work, DynamicState& next);

// One step of the three-stage Radau IIA scheme (solver/integrators/radau.cpp) of size h from
// `state` into `next`; t_new as for the generalized-alpha step. Under error control the outcome
// carries the step's local error estimate (StepOutcome::error_q, error_v).
StepOutcome RadauStep(const SystemModel& model, const DofMap& dofs, const DynamicOptions& options,
                      const DynamicState& state, double h, double t_new, IterationMatrix& matrix, BodyThreads& threads,
                      BodyWorkspace& work, DynamicState& next);
// The Radau IIA step's Newton system at the stage accelerations A (a step of h from `state`): the
// three stages' residuals over the solved unknowns, stage after stage, each row scaled as the
// iteration matrix's (1 / h^2 on a constraint equation), and with `matrix` the iteration matrix
// there, -d(residual)/dA, from each stage's own K, C and M (every body's computed; `options`:
// full_inertia_tangent). For the tests of the matrix against differences of the residuals.
Eigen::VectorXd RadauStageResiduals(const SystemModel& model, const DofMap& dofs, const DynamicOptions& options,
                                    const DynamicState& state, double h, const std::array<Eigen::VectorXd, 3>& A,
                                    BodyWorkspace& work, Eigen::MatrixXd* matrix = nullptr);

// One step of options.integrator (the steps above).
inline StepOutcome IntegratorStep(const SystemModel& model, const DofMap& dofs, const DynamicOptions& options,
                                  const DynamicState& state, double h, double t_new, IterationMatrix& matrix,
                                  BodyThreads& threads, BodyWorkspace& work, DynamicState& next) {
  switch (options.integrator) {
    case Integrator::kMidpoint:
      return MidpointStep(model, dofs, options, state, h, t_new, matrix, threads, work, next);
    case Integrator::kRadau:
      return RadauStep(model, dofs, options, state, h, t_new, matrix, threads, work, next);
    case Integrator::kGeneralizedAlpha:
      break;
  }
  return GeneralizedAlphaStep(model, dofs, options, state, h, t_new, matrix, threads, work, next);
}

}  // namespace femb::dynamic_internal
