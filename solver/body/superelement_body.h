// A superelement in absolute interface coordinates (thesis ch. 3-4, 8.1; tangent stiffness paper).
//
// System coordinates of one body: for each interface node k its position x_k and rotation R_k
// (variations dx_k, spatial dpi_k), then the internal modal coordinates eta. The floating frame
// (x_j, R_j) is not a coordinate: it solves Phi_CB q_loc = 0 (thesis 3.7, 4.2) by Newton.
//
// Local coordinates (thesis 3.1): u_k = R_j^T (x_k - x_j) - X_k,
//   theta_k = log(R_j^T R_k R0_k^T), eta.
// Their variation, exact to first order:  d q_loc = B Rbar^T d q,  B = D T  with
//   D = blockdiag(1, J_l^-1(theta_k), 1)         (exact rotation kinematics; the thesis uses D = 1)
//   Phi_rig rows [1, -r~_k; 0, 1], r_k = X_k + u_k (thesis 3.14)
//   S = Phi_CB D Phi_rig, Z = S^-1 Phi_CB D       (thesis 3.17 with D)
//   T = 1 - Phi_rig Z                              (thesis 3.18)
// Elastic force, the gradient of V = q_loc^T K q_loc / 2:  f = Rbar B^T K q_loc  (thesis 4.12).
// With modal derivatives (thesis 8.3) V is the file's quartic polynomial (Green-Lagrange inside
// the body) and K q_loc becomes its gradient Q(q_loc), K its Hessian in K1; K2-K4 use Q as they
// are written.
// Tangent (exact derivative, checked against finite differences), local part of
// K_t = Rbar (K1 + K2 + K3 + K4) Rbar^T:
//   K1 = B^T K B                                   (thesis 4.25)
//   K2 = -Z^T Fhat^T B,  Fhat from Qhat = B^T K q   (thesis 4.32)
//   K3 = -(Fhat + Mhat) Z                           (thesis 4.37)
//   K4 = T^T G B, G = blockdiag(d/dtheta [J_l^-T(theta_k) v_k]), v = P^T K q,
//        P = 1 - D Phi_rig S^-1 Phi_CB              (from D; zero when D = 1)
// Option `approximated` (thesis 3.23, 5.3): the force uses the constant T0 = 1 - Phi_rig0 Phi_CB,
// f = Rbar T0^T K q_loc; its tangent is the exact derivative of that force.
#pragma once

#include <Eigen/Core>
#include <array>
#include <optional>
#include <vector>

#include "formats/superelement.h"

namespace femb {

struct SuperelementOptions {
  bool approximated = false;             ///< Phi_rig0 / constant T0 (thesis 5.3) instead of the deformed Phi_rig
  bool full_tangent = true;              ///< false: K1 only (the paper shows Newton then fails at high load)
  bool quadratic_velocity_terms = true;  ///< false: inertia force M_g wdot only (thesis 4.11 remark)
  bool cardona_option_b = false;         ///< angular velocities in node frames R_k^T (Cardona's option B)
  double modal_damping = 0.0;            ///< damping ratio zeta of the internal modes: f = 2 zeta omega etadot
  /// With modal derivatives in the file: the local internal force is its cubic polynomial
  /// (formats/reduced_polynomial.h, Green-Lagrange inside the body) instead of K q_loc.
  bool polynomial_force = true;
  /// Geometric stiffening from the file: the quadratic Green-Lagrange force of a file
  /// without modal derivatives and the inertia load cases' geometric stiffness. false: ignored.
  bool geometric_stiffening = true;
  /// With the file's inertia invariants (formats/superelement.h inertia_gamma, inertia_xi): the
  /// exact kinetic energy of the reduced field in the floating frame (SuperelementBody, "Exact
  /// inertia") in the generalized-alpha and static analyses. false, or a file without them: the
  /// corotational kinetic energy of the thesis (3.22). The midpoint scheme always uses the latter.
  bool exact_inertia = true;
};

/// The 12 inertia load factors of a body's floating frame (formats/superelement.h
/// kInertiaLoadCases) and their derivatives with respect to the body's velocities and
/// accelerations (12 x n each). See SuperelementBody::InertiaLoads.
struct InertiaLoadFactors {
  Eigen::Matrix<double, 12, 1> a = Eigen::Matrix<double, 12, 1>::Zero();
  Eigen::MatrixXd d_w, d_wdot;
};

/// Velocities of one body's system coordinates: per node xdot_k, omega_k (spatial), then etadot.
using BodyVelocity = Eigen::VectorXd;

/// Configuration of one body's system coordinates.
struct BodyConfiguration {
  std::vector<Eigen::Vector3d> x;  ///< interface node positions (global)
  std::vector<Eigen::Matrix3d> R;  ///< interface node rotations (global)
  Eigen::VectorXd eta;             ///< internal modal coordinates
};

/// The floating frame of a configuration.
struct FrameSolution {
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  int iterations = 0;
  bool ok = false;
};

/// A body's velocity maps at one configuration, for evaluating several momentum terms there:
/// P (system velocities -> local velocities), U (the floating frame's angular velocity map,
/// 3 x n) and M_g = P^T M P.
struct BodyVelocityMaps {
  Eigen::MatrixXd P, U, Mg;
};

/// Scratch storage of a body's kernels at one configuration (SuperelementBody::Data::scratch):
/// the temporaries of the forces and matrices, kept with the data from one Newton iteration to
/// the next so that evaluating a body allocates nothing once they have their sizes.
/// Their contents mean nothing between calls. One matrix per shape and use in an iteration (a
/// resize to another number of entries would allocate): n x n, n x 6 (or 6 x n), n x 3 (3 x n).
struct BodyScratch {
  Eigen::VectorXd v1, v2, v3, v4;
  Eigen::MatrixXd nn1, nn2, n6a, n6b, n6c, n3a, n3b, n3c;
};

/// The exact inertia's temporaries (ExactInertiaForce, ExactGyroscopic), as BodyScratch.
struct ExactScratch {
  Eigen::VectorXd Rw, qd, r, y, yd, pi_q, pi_q_dot, f_q, t1, t2, S_ab, p_hat, g;
  Eigen::MatrixXd Hd, dxi, dv, dOm, dqd, dr, dOmd, dy, G_Om, Gty, base, df_q, G_skew, GtP, dh, dhd, dpi_xi, PH, df_xi,
      PG, dpi_v, dpi_w, t3, t4, t5, t6, t7, t8;
  Eigen::RowVectorXd row, row2;
};

/// Immutable model of one superelement (from its file) plus its placement in the scene.
class SuperelementBody {
 public:
  /// `placement_R`, `placement_x` map part coordinates to global ones (x = p + R_p X).
  SuperelementBody(const Superelement& se, const SuperelementOptions& options,
                   const Eigen::Matrix3d& placement_R = Eigen::Matrix3d::Identity(),
                   const Eigen::Vector3d& placement_x = Eigen::Vector3d::Zero());

  /// The configuration-dependent quantities of the kinematics (thesis 3.14-3.18; see the file
  /// comment): Phi_rig, D, S = Phi_CB D Phi_rig, Z = S^-1 Phi_CB D, T = 1 - Phi_rig Z, B = D T.
  struct Kinematics {
    Eigen::MatrixXd Phi_rig;            ///< n x 6
    std::vector<Eigen::Matrix3d> Jinv;  ///< D's rotation blocks J_l^-1(theta_k) (D is 1 elsewhere)
    Eigen::Matrix<double, 6, 6> S, S_inv;
    Eigen::MatrixXd W;  ///< Phi_CB D (6 x n)
    Eigen::MatrixXd Z;  ///< 6 x n
    Eigen::MatrixXd T;  ///< n x n
    Eigen::MatrixXd B;  ///< n x n
  };
  /// The exact inertia's configuration-dependent products (has_exact_inertia).
  struct ExactData {
    Eigen::MatrixXd Y;   ///< Phi_rig0 Z + B
    Eigen::MatrixXd H;   ///< n x 3: Gamma_a q
    Eigen::MatrixXd XQ;  ///< n x 9: Xi_ab q in column 3 a + b (Xi_ba = Xi_ab^T)
    Eigen::Matrix3d Xq;  ///< q^T Xi_ab q
    /// For the matrices only (ExactMass, ExactGyroscopic), made when first asked (has_products):
    /// M Y and H^T Y (3 x n).
    Eigen::MatrixXd MY, HtY;
    // No default member initializer: clang then finds ExactData not default-constructible while
    // SuperelementBody is incomplete (std::optional<ExactData> in Data). Exact sets it.
    bool has_products;
    Eigen::VectorXd xq;  ///< scratch of Exact
  };
  /// Everything one configuration of the body determines, computed once (Evaluate) and passed to
  /// every force, matrix and energy evaluated there: an assembly pass evaluates each body's
  /// kinematics once instead of once per term (the model / data split). The body (the model) is
  /// const; the kernels take the data by reference and leave in it what they computed for the
  /// next kernel at the same configuration (the maps, the exact mass, the local force, the
  /// stiffening's products, each with its flag, cleared by Evaluate) and their temporaries.
  struct Data {
    BodyConfiguration c;
    FrameSolution frame;
    Eigen::VectorXd q;  ///< q_loc
    Kinematics kin;
    std::optional<ExactData> exact;  ///< with the exact inertia (kept: its storage reused)
    BodyVelocityMaps maps;           ///< the corotational maps, made when first asked (has_maps)
    bool has_maps = false;
    Eigen::MatrixXd exact_mass;  ///< M_g of the exact inertia, made when first asked (has_exact_mass)
    bool has_exact_mass = false;
    /// The local force Q (LocalForce) of the last load factors asked for, and with inertia
    /// stiffening the products K_sigma,k q_loc (n x 12): the residual and the matrix passes of an
    /// iteration share them.
    struct LocalForceOf {
      Eigen::Matrix<double, 12, 1> a;  ///< the load factors (zero: none)
      Eigen::VectorXd Q;
      bool valid = false;
    };
    LocalForceOf local_force;
    Eigen::MatrixXd sigma_q;  ///< when has_sigma_q
    bool has_sigma_q = false;
    Eigen::VectorXd eps;  ///< the condensed polynomial's q + K^+ A z, made when first asked (has_eps)
    bool has_eps = false;
    PolynomialScratch polynomial_scratch;
    BodyScratch scratch;         ///< the kernels' temporaries (BodyScratch)
    ExactScratch exact_scratch;  ///< the exact inertia's (ExactScratch)
  };
  /// The body's quantities at configuration `c` with its solved floating frame.
  Data Evaluate(const BodyConfiguration& c, const FrameSolution& frame) const;
  /// The same into `d`, reusing its storage (a body's data kept from one Newton iteration to the
  /// next allocates nothing for the kinematics). `c` may be d.c itself.
  void Evaluate(const BodyConfiguration& c, const FrameSolution& frame, Data& d) const;
  /// The same when d.q already holds the local coordinates at `frame` (SolveFrameFrom's output
  /// for this c and frame): they are not computed again.
  void EvaluateSolved(const BodyConfiguration& c, const FrameSolution& frame, Data& d) const;
  /// The velocity maps of `d` (computed on the first call).
  const BodyVelocityMaps& MapsOf(Data& d) const;

  int n_nodes() const { return n_nodes_; }
  int n_modes() const { return n_modes_; }
  int n_coordinates() const { return 6 * n_nodes_ + n_modes_; }
  const Eigen::MatrixXd& K() const { return K_; }
  const Eigen::MatrixXd& M() const { return M_; }
  const SuperelementOptions& options() const { return options_; }
  /// Force of round-off size for this body (ForceNorm units): 1e-4 max|D K D| times its size.
  /// Newton tolerances are relative to force scales floored by this, so that nearly unloaded
  /// states converge.
  double force_floor() const { return force_floor_; }
  /// |f| of a body vector (per node force then moment, then modal forces) in force units in any
  /// unit system: moments divided by the body's size, modal forces (force / sqrt(mass): the
  /// modes are mass-normalized) times sqrt of its mass.
  double ForceNorm(const Eigen::VectorXd& f) const { return (force_weights_.asDiagonal() * f).norm(); }
  /// The weight of the modal forces in ForceNorm: sqrt of the body's mass.
  double ModalForceWeight() const { return modal_weight_; }
  /// The residual noise that the round-off of absolute node positions of magnitude |x| causes
  /// in the elastic force and, in a time step whose iteration matrix takes the mass times
  /// `inertia_factor` (generalized-alpha beta', the midpoint scheme 2 / h^2: the accelerations
  /// are position differences over h^2), in the inertia force (ForceNorm units):
  /// eps |x| (16 sqrt(n) max|D K D| + 4 inertia_factor max|D M D|): the inertia's share is the
  /// round-off of the position differences in the momenta of a step (measured: the midpoint
  /// scheme's residual on a rigid four-bar at h = 5 us stalls at 1.25 times eps |x| 2 beta' |M|;
  /// 16 sqrt(n) there let it stop short of its invariants at Newton tolerance 1e-12). Far from
  /// the origin (1e4 m), or with steps of microseconds, it exceeds a relative Newton tolerance;
  /// the analyses accept a residual below it.
  double RoundOffForce(const BodyConfiguration& c, double inertia_factor = 0.0) const;

  /// Undeformed configuration at the placement, and its floating frame.
  BodyConfiguration InitialConfiguration() const;
  FrameSolution InitialFrame() const { return initial_frame_; }

  /// A starting guess for SolveFrame with no previous frame: the frame carried rigidly by
  /// interface node 0.
  FrameSolution GuessFrame(const BodyConfiguration& c) const;

  /// Newton on Phi_CB q_loc(x_j, R_j) = 0 from `guess` (thesis 4.2). ok = false when the
  /// residual does not fall below 1e-12 (relative) in 30 iterations. `q`: scratch for the local
  /// coordinates (no allocation once sized; on return they are the solution's), or none. With
  /// `S_inv` (the inverse frame matrix of a nearby configuration of this body, e.g. its last
  /// Kinematics::S_inv) the iteration uses it instead of factoring the frame matrix at every
  /// iterate: S depends on the deformation only, so it converges as fast while it costs a 6 x 6
  /// product per iteration.
  FrameSolution SolveFrame(const BodyConfiguration& c, const FrameSolution& guess, Eigen::VectorXd* q = nullptr,
                           const Eigen::Matrix<double, 6, 6>* S_inv = nullptr) const;
  /// SolveFrame from the last frame (with `S_inv` first, then full Newton), and failing that
  /// from GuessFrame (ok = false if every attempt fails).
  FrameSolution SolveFrameFrom(const BodyConfiguration& c, const FrameSolution& last, Eigen::VectorXd* q = nullptr,
                               const Eigen::Matrix<double, 6, 6>* S_inv = nullptr) const;

  /// The coordinates the modal stresses are taken at: q_loc, or with the geometric stiffening's
  /// condensed polynomial its eps = q + K^+ A z (formats/reduced_polynomial.h).
  Eigen::VectorXd StressCoordinates(const Eigen::VectorXd& q) const {
    return polynomial_ ? femb::StressCoordinates(*polynomial_, q) : q;
  }
  /// Local coordinates q_loc (6N + m) into `q`.
  void LocalCoordinates(const BodyConfiguration& c, const FrameSolution& frame, Eigen::VectorXd& q) const;

  /// Elastic force f (6N + m; per node force then moment, global axes; then modal forces) and,
  /// if `tangent` is not null, its derivative with respect to (dx_k, dpi_k, d eta).
  /// With `load` (and a file with inertia stiffening) the local stiffness is K + K_sigma(a)
  /// (InertiaLoads); `d_load` (n x 12) then receives df/da at fixed configuration.
  void ElasticForce(Data& d, Eigen::VectorXd* f, Eigen::MatrixXd* tangent, const InertiaLoadFactors* load = nullptr,
                    Eigen::MatrixXd* d_load = nullptr) const;

  /// Thesis 8.2 case 4: a basis that moves only m < 6N interface directions holds the others
  /// with the file's C q_int = 0 (formats/superelement.h interface_constraint; r rows, lengths).
  /// femb-solve adds it to the system with Lagrange multipliers (solver/joints/loop_constraints.h).
  int n_constraints() const { return int(C_.rows()); }
  /// At `d`: g = C q_int (r); G = dg/dq = C B Rbar^T on the body's coordinates (r x n, exact: the
  /// local map of the file comment); with `lambda`, H = d(G^T lambda)/dq (n x n). G^T lambda is
  /// the elastic force's form Rbar B^T Q with the local force Q = [C^T lambda; 0], which does not
  /// depend on the configuration: H is that force's K2 + K3 + K4 (tangent stiffness paper).
  void InterfaceConstraint(Data& d, Eigen::VectorXd* g, Eigen::MatrixXd* G, const Eigen::VectorXd* lambda,
                           Eigen::MatrixXd* H) const;

  /// True when the body uses the geometric stiffness of inertia load cases (file and option).
  bool has_inertia_stiffening() const { return !K_sigma_.empty(); }

  /// Stiffening from rigid-body inertia loads (Wallrapp's standard input data, the SID
  /// of Simpack; Cardona 2000 for the superelement setting). The reducer stored
  /// K_sigma,k = Phi^T G(sigma_k) Phi for the stress sigma_k of the k-th unit inertia field with
  /// the interfaces held; the body's local stiffness is K + sum_k a_k K_sigma,k with a_k the
  /// floating frame's current values, in frame axes:
  ///   a_0..2  = R_j^T (xddot_j - g)          (frame origin acceleration, gravity: d'Alembert)
  ///   a_3..5  = alpha                        (angular acceleration)
  ///   a_6..11 = w_x^2, w_y^2, w_z^2, w_x w_y, w_x w_z, w_y w_z   (omega x (omega x r) field)
  /// The frame's velocity [v_j; omega] = Z Rbar^T w (thesis 3.17); its acceleration from the
  /// nodes' accelerations with the centrifugal part of a rigid motion taken out, which Z maps
  /// exactly (Z Phi_rig = 1): for a rigid motion R_j^T xddot_k = a_j + alpha x r_k + omega x (omega x r_k)
  /// and R_j^T omegadot_k = alpha, so [a_j; alpha] = Z (Rbar^T wdot - c(omega)),
  /// c_k = omega x (omega x r_k) on node k's translation rows. d_w and d_wdot are exact at fixed
  /// configuration (the configuration dependence of R_j and Z is left out of the tangent).
  /// Into `out` (its storage reused).
  void InertiaLoads(Data& d, const BodyVelocity& w, const BodyVelocity& wdot, const Eigen::Vector3d& gravity,
                    InertiaLoadFactors& out) const;

  /// Strain energy q_loc^T K q_loc / 2.
  double ElasticEnergy(Data& d) const;

  /// True when the body uses the exact kinetic energy (file invariants and option exact_inertia).
  ///
  /// Exact inertia. The reduced field in frame axes is X + Phi q_loc, its velocity
  /// v_j + Omega x (X + Phi q_loc) + Phi qdot_loc, so with y = Phi_rig0 xi + qdot_loc,
  /// xi = (v_j, Omega) = Z Rbar^T w and qdot_loc = B Rbar^T w (thesis 3.17), the kinetic energy of
  /// the full model's mass is (Wallrapp's floating frame of reference form, the invariants
  /// Gamma_a, Xi_ab of formats/superelement.h)
  ///   T = y^T M y / 2 + y^T Gamma(Omega) q + q^T Xi(Omega) q / 2,
  ///   Gamma(Omega) = sum_a Omega_a Gamma_a,  Xi(Omega) = sum_ab Omega_a Omega_b Xi_ab.
  /// The thesis' T = (Rbar^T w)^T M (Rbar^T w) / 2 differs from it at the order of q Omega: it
  /// turns the interface displacements with the frame but interpolates them with the modes
  /// (Omega x u_k at the nodes in place of Omega x (Phi q) in the body; the internal modes not at
  /// all), and it takes the interface angular velocities for the rates of the local rotations
  /// (J_l(theta) thetadot for thetadot); for a rotating cantilever that gave in-plane softening
  /// -1.34 Omega^2 instead of -Omega^2 and a flapwise softening -0.3 Omega^2 that has no physical
  /// cause (a gyroscopic coupling of tip torsion and tip slope through the momentum of the
  /// rotating body). The equations of motion: Kirchhoff's for the frame,
  ///   f_xi = d/dt dT/dxi + [Omega x pi_v; Omega x pi_Omega + v x pi_v],
  /// Lagrange's for the local coordinates, f_q = d/dt dT/dqdot - dT/dq, and by virtual work
  /// (delta xi = Z Rbar^T dq, delta q_loc = B Rbar^T dq) f_in = Rbar (Z^T f_xi + B^T f_q). The
  /// accelerations: differentiating Rbar^T w = Phi_rig xi + D^-1 qdot_loc (with Phi_CB qdot_loc
  /// = 0) gives xidot = Z r, qddot_loc = B r, r = Rbar^T wdot - c, c = Omega^ Rbar^T w
  /// + [Omega x udot_k; (d/dt J_l(theta_k)) thetadot_k] on the node rows. T = w^T M_g w / 2 with
  /// M_g = Rbar (Y^T M Y + Y^T H Z_r + Z_r^T H^T Y + Z_r^T X_q Z_r) Rbar^T, Y = Phi_rig0 Z + B,
  /// Z_r the rotation rows of Z, H = [Gamma_a q], (X_q)_ab = q^T Xi_ab q.
  bool has_exact_inertia() const { return !Gamma_.empty(); }

  /// The floating frame's motion and the rates of the local coordinates at `d` (thesis 3.17 and
  /// its derivative, see "Exact inertia" above): xi = (V, Omega) = Z Rbar^T w, the frame origin's
  /// velocity and the frame's angular velocity in frame axes; qdot_loc = B Rbar^T w; with `wdot`
  /// also xidot = (Vdot, Omegadot) = Z r and qddot_loc = B r, r = Rbar^T wdot - c (zero
  /// without). A material point at s = X + Phi(X) q_loc from the frame origin (frame axes) then
  /// moves with x = x_j + R_j s, v = R_j (V + Omega x s + Phi qdot_loc) and
  /// a = R_j (Vdot + Omega x V + Omegadot x s + Omega x (Omega x s) + 2 Omega x Phi qdot_loc
  /// + Phi qddot_loc).
  struct LocalMotion {
    Eigen::Vector3d V = Eigen::Vector3d::Zero(), Omega = Eigen::Vector3d::Zero();
    Eigen::Vector3d Vdot = Eigen::Vector3d::Zero(), Omegadot = Eigen::Vector3d::Zero();
    Eigen::VectorXd qdot, qddot;
  };
  LocalMotion LocalRates(Data& d, const BodyVelocity& w, const BodyVelocity* wdot) const;

  /// Inertia force from the corotational kinetic energy T = v^T M v / 2, v = P w (thesis 3.22,
  /// 4.9; DESIGN.md "Inertia"), P = blockdiag(R_j^T ... , 1) (option A) or with R_k^T on the
  /// angular rows (option B). With G defined by d(P w) = P G dq and Omega_P, Omega_hat the
  /// block-diagonal skew matrices of Pdot^T = Omega_P P^T and of the node angular velocities:
  ///   f_in = M_g wdot + M_g G w + (Omega_P - Omega_hat) p - G^T p,  M_g = P^T M P, p = M_g w.
  /// `mass` receives M_g, `gyroscopic` d f_in / d w (exact: f_in is quadratic in w).
  /// `f_acc` (optional) receives the part linear in wdot, M_g wdot.
  void InertiaForce(Data& d, const BodyVelocity& w, const BodyVelocity& wdot, Eigen::VectorXd* f_in,
                    Eigen::MatrixXd* mass, Eigen::MatrixXd* gyroscopic, Eigen::VectorXd* f_acc = nullptr) const;

  /// d f_in / dq at fixed (w, wdot): d(M_g wdot)/dq = MomentumDerivative(MapsOf(d), wdot)
  /// (exact), plus with `quadratic` the configuration derivative of the quadratic velocity terms
  /// by central differences (2n evaluations with the frame re-solved; steps 1e-7 of the body
  /// size, 1e-7 rad, 1e-7 of the modal scale). Into `tangent` (its storage reused).
  void InertiaConfigurationTangent(Data& d, const BodyVelocity& w, const BodyVelocity& wdot, bool quadratic,
                                   Eigen::MatrixXd& tangent) const;

  /// Modal damping force 2 zeta omega_i etadot_i on the internal-mode rows and its derivative
  /// with respect to w (added to `f` and `C`).
  void AddModalDamping(const BodyVelocity& w, Eigen::VectorXd& f, Eigen::MatrixXd* C) const;

  /// M_g w, into d.scratch.v1 (the exact inertia: without forming M_g).
  const Eigen::VectorXd& MassTimes(Data& d, const BodyVelocity& w) const;
  /// The mass matrix d^2 T / dw^2 at `d`: the exact one or the corotational M_g (MapsOf).
  const Eigen::MatrixXd& Mass(Data& d) const { return has_exact_inertia() ? ExactMass(d) : MapsOf(d).Mg; }
  /// Kinetic energy v^T M v / 2.
  double KineticEnergy(Data& d, const BodyVelocity& w) const;

  /// d p / d q at fixed w (n x n; per node (dx, dpi) spatial, then d eta): the configuration
  /// derivative of the generalized momentum (midpoint iteration matrix; with w = wdot, the
  /// configuration derivative of M_g wdot). The maps are MapsOf's (BodyVelocityMaps); into `D`
  /// with the temporaries in `scratch` (no allocation once sized).
  void MomentumDerivative(const BodyVelocityMaps& maps, const BodyVelocity& w, Eigen::MatrixXd& D,
                          BodyScratch& scratch) const;

  /// The momentum balance in the form dp/dt = s(q, w, p) + applied - elastic forces, with
  ///   s = G^T p + Omega_hat p    (dT/dq at fixed spatial velocities, and omega_k x p_k on the
  /// rotation rows from the spatial velocities of SO(3)), so that f_in = dp/dt - s. Here p is
  /// any vector (the midpoint scheme passes the momenta of the step's ends). For every p, s has
  /// no resultant and its moment about the origin is sum_k p_x,k x xdot_k: this is what makes the
  /// midpoint scheme of dynamic_analysis.h conserve linear and angular momentum exactly.
  /// Into `out` with the temporaries in `scratch` (no allocation once sized).
  void MomentumSource(const BodyVelocityMaps& maps, const BodyVelocity& w, const Eigen::VectorXd& p,
                      Eigen::VectorXd& out, BodyScratch& scratch) const;
  /// The whole source at `d` for the body's own kinetic energy: with the exact inertia
  ///   s = G^T p + Omega_hat p + Rbar B^T g,
  /// g = dT/dq_loc at fixed frame-axes velocities Rbar^T w (the local coordinates' own share:
  /// the invariants' explicit terms and the turning of the maps Z, B with q_loc; see
  /// ExactMomentumSource), which, orthogonal to every rigid motion, adds no resultant and no
  /// moment: the midpoint scheme keeps conserving momentum. Here p is the exact momentum
  /// MassTimes(d, w) for the G^T p part only where the caller passes it so; the local term
  /// takes the momentum of w at d itself. Without the exact inertia: MomentumSource(MapsOf(d)).
  void MomentumSource(Data& d, const BodyVelocity& w, const Eigen::VectorXd& p, Eigen::VectorXd& out) const;

  /// d p / d q at fixed w of the body's own momentum p = MassTimes(d, w) (the midpoint scheme's
  /// iteration matrix): MomentumDerivative for the corotational inertia; for the exact one the
  /// frame's turning as MomentumDerivative with the exact mass plus the local coordinates' share
  /// Rbar (d p_hat / d q_loc) B Rbar^T, the middle factor by central differences in q_loc (that
  /// share turns the torsion of a spinning bar, whose inertia is small, as much as the frame's:
  /// without it Newton stalled there). `side`: the perturbed data (storage reused).
  void MomentumConfigurationTangent(Data& d, const BodyVelocity& w, Data& side, Eigen::MatrixXd& D) const;
  /// With the exact inertia: adds to `d_w` the derivative of the source's local term (the
  /// MomentumSource at `d` beyond G^T p + Omega_hat p) with respect to w, by central
  /// differences that are exact up to round-off (the term is quadratic in w).
  void AddLocalSourceVelocityDerivative(Data& d, const BodyVelocity& w, Eigen::MatrixXd& d_w) const;
  /// Derivatives of MomentumSource s(q, w, p) with respect to w and to p (both n x n; s is
  /// bilinear in w and p), with the temporaries in `scratch` (no allocation once d_w, d_p are sized).
  void MomentumSourceDerivatives(const BodyVelocityMaps& maps, const BodyVelocity& w, const Eigen::VectorXd& p,
                                 Eigen::MatrixXd& d_w, Eigen::MatrixXd& d_p, BodyScratch& scratch) const;

  /// Linear momentum and angular momentum about the global origin (Noether: sums of the
  /// generalized momenta p = M_g w of the nodes).
  void Momentum(Data& d, const BodyVelocity& w, Eigen::Vector3d* linear, Eigen::Vector3d* angular) const;
  /// The same from the generalized momentum p = M_g w (MassTimes).
  void MomentumFrom(Data& d, const Eigen::VectorXd& p, Eigen::Vector3d* linear, Eigen::Vector3d* angular) const;

  /// The deformed body's centre of mass (global): x_j + R_j (s_0 + C q_loc) / m, s_0 the first
  /// moment of the undeformed body about the frame origin, C = int rho Phi (the translation rows
  /// of Phi_rig0^T M), m the mass; from the local coordinates q_loc = LocalCoordinates(c, frame).
  Eigen::Vector3d CenterOfMass(const Eigen::VectorXd& q_loc, const FrameSolution& frame) const;
  /// The body's mass.
  double mass() const { return mass_; }

  /// Generalized force of a uniform acceleration field g (gravity): P^T M Phi_rig0 [R_j^T g; 0].
  /// Into `f` (its storage reused).
  void GravityForce(Data& d, const Eigen::Vector3d& g, Eigen::VectorXd& f) const;
  /// d GravityForce / dq (n x n): the weight's distribution over the nodes and modes turns with
  /// the floating frame. Corotational inertia: GravityForce = M_g wdot_g (wdot_g = g on the node
  /// translations), so MomentumDerivative(maps, wdot_g), exact; exact inertia: central
  /// differences (steps as in InertiaConfigurationTangent). A pendulum hanging from a pin owes
  /// its whole restoring stiffness to it.
  Eigen::MatrixXd GravityTangent(Data& d, const Eigen::Vector3d& g) const;

 private:
  // Into `k`, reusing its storage.
  void ComputeKinematics(const Eigen::VectorXd& q_loc, Kinematics& k) const;
  // S = Phi_CB D Phi_rig alone (the floating frame's Newton iteration), node block by node block.
  Eigen::Matrix<double, 6, 6> FrameMatrix(const Eigen::VectorXd& q_loc) const;
  // P (system velocities -> local velocities) and the frame's angular velocity map U (3 x n).
  void VelocityMaps(Data& d, Eigen::MatrixXd* P, Eigen::MatrixXd* U) const;
  // G of d(P w) = P G dq at fixed w (n x n, into G), from U and the velocities.
  void VelocityMapRate(const Eigen::MatrixXd& U, const BodyVelocity& w, Eigen::MatrixXd& G) const;
  // The quadratic part of f_in: M_g G w + (Omega_P - Omega_hat) p - G^T p.
  void QuadraticInertia(const Eigen::MatrixXd& U, const Eigen::MatrixXd& Mg, const BodyVelocity& w,
                        Eigen::VectorXd& out, BodyScratch& scratch) const;
  // Its derivative by w (exact, O(n^2) products), into D.
  void QuadraticInertiaDerivative(const Eigen::MatrixXd& U, const Eigen::MatrixXd& Mg, const BodyVelocity& w,
                                  Eigen::MatrixXd& D, BodyScratch& scratch) const;
  Eigen::MatrixXd Phi_rig0_;
  // CenterOfMass: the mass m, the undeformed first moment s_0 about the frame origin, and C.
  double mass_ = 0.0;
  Eigen::Vector3d first_moment0_ = Eigen::Vector3d::Zero();
  Eigen::MatrixXd first_moment_map_;  ///< 3 x n
  // Exact inertia (has_exact_inertia): per-configuration data (into `d`, its storage reused), the
  // force, the mass matrix M_g.
  void Exact(const Eigen::VectorXd& q, const Kinematics& kin, ExactData& d) const;
  // With `f_acc`, also the part linear in wdot alone (M_g wdot) from the same products.
  void ExactInertiaForce(Data& d, const BodyVelocity& w, const BodyVelocity& wdot, Eigen::VectorXd& f,
                         Eigen::VectorXd* f_acc) const;
  // M Y and H^T Y of d.exact, made on the first call.
  const ExactData& ExactProducts(Data& d) const;
  const Eigen::MatrixXd& ExactMass(Data& d) const;  // computed once per Data
  // d f_in / d w of the exact inertia force (forward mode, exact).
  void ExactGyroscopic(Data& d, const BodyVelocity& w, Eigen::MatrixXd& G) const;
  void ExactMassTimesTurned(Data& data, const Eigen::VectorXd& r, Eigen::VectorXd& out) const;
  // c = Rbar B^T g, g = dT/dq_loc at fixed Rbar^T w (MomentumSource(Data&, ...)), into out.
  void ExactMomentumSource(Data& data, const BodyVelocity& w, Eigen::VectorXd& out) const;
  Eigen::MatrixXd ExactInertiaConfigurationTangent(Data& d, const BodyVelocity& w, const BodyVelocity& wdot) const;
  BodyConfiguration Perturbed(const BodyConfiguration& c, int i, double sign, double* step) const;
  // r -= c(Omega, Rbar^T w, qdot_loc) at local coordinates q (LocalRates, ExactInertiaForce).
  void SubtractRateTerms(const Eigen::VectorXd& q, const Eigen::Vector3d& Om, const Eigen::VectorXd& Rw,
                         const Eigen::VectorXd& qd, Eigen::VectorXd& r) const;
  std::vector<Eigen::MatrixXd> Gamma_;  ///< the file's inertia invariants Gamma_a (3), or none
  // The invariants stacked for one matrix-vector product each: [Gamma_0; Gamma_1; Gamma_2]
  // (3n x n) and Xi_ab at row block 3 a + b (9n x n, Xi_ba = Xi_ab^T); Phi_rig0^T M (6 x n).
  Eigen::MatrixXd Gamma_stack_, Xi_stack_, PtM_;
  // [Gamma_0 v, Gamma_1 v, Gamma_2 v] (n x 3) from the stack, into `out` (its storage reused).
  void GammaColumns(const Eigen::VectorXd& v, Eigen::MatrixXd& out) const;

  int n_nodes_ = 0, n_modes_ = 0;
  SuperelementOptions options_;
  Eigen::MatrixXd K_, M_, Phi_CB_;
  Eigen::MatrixXd C_;  ///< interface constraint (r x 6N; no rows: none)
  // K2 + K3 + K4 of a local force Q (Qhat = B^T Q, or T0^T Q when `approximated`: K3 alone),
  // added to the local Kt (not turned by Rbar).
  void AddGeometricTangent(Data& d, const Eigen::VectorXd& Q, const Eigen::VectorXd& Qhat, bool approximated,
                           Eigen::MatrixXd& Kt) const;
  std::optional<PolynomialStiffness> polynomial_;  ///< set when the file has it and the option is on
  // Local internal force and its tangent: K q or the polynomial's.
  // The force is kept in d (Data::local_force) for the next call with the same load factors.
  const Eigen::VectorXd& LocalForce(Data& d, const InertiaLoadFactors* load = nullptr) const;
  // Into K.
  void LocalTangent(Data& d, const InertiaLoadFactors* load, Eigen::MatrixXd& K) const;
  // The condensed polynomial's eps at d (geometric stiffening without modal derivatives), kept in d.
  const Eigen::VectorXd& Condensed(Data& d) const;
  // K_sigma,k q_loc for the 12 load cases (n x 12), kept in d.
  const Eigen::MatrixXd& SigmaProducts(Data& d) const;
  std::vector<Eigen::MatrixXd> K_sigma_;  ///< the 12 inertia load case geometric stiffnesses, or none
  Eigen::MatrixXd K_sigma_stack_;         ///< the same stacked (12n x n)
  std::vector<Eigen::Vector3d> X_;        ///< node positions relative to the frame origin, frame axes
  std::vector<Eigen::Matrix3d> R0_;       ///< node orientations relative to the frame
  Eigen::MatrixXd T0_;                    ///< 1 - Phi_rig0 Phi_CB (approximated option)
  Eigen::Matrix3d placement_R_;
  Eigen::Vector3d placement_x_;
  Eigen::Vector3d origin_part_;
  FrameSolution initial_frame_;
  double force_floor_ = 0.0;
  double k_max_ = 0.0;             ///< max|D K D|, D = diag(force_weights_): force per length
  double m_max_ = 0.0;             ///< max|D M D|: force per acceleration
  Eigen::VectorXd force_weights_;  ///< see ForceNorm
  double modal_weight_ = 1.0;
};

}  // namespace femb
