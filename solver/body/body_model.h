// The model of one superelement body: its file's reduced matrices and invariants, the options
// it is used with and its placement in the scene, set once (SuperelementBody); and the data of one
// evaluation at a configuration (BodyData), which the kernels (solver/body/superelement_body.h)
// fill and read: f(const SuperelementBody&, BodyData&, inputs).
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
/// accelerations (12 x n each). See InertiaLoads (inertia_stiffening.h).
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

/// Scratch storage of a body's kernels at one configuration (BodyData::scratch):
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

/// The configuration-dependent quantities of the kinematics (thesis 3.14-3.18; see the file
/// comment): Phi_rig, D, S = Phi_CB D Phi_rig, Z = S^-1 Phi_CB D, T = 1 - Phi_rig Z, B = D T.
struct BodyKinematics {
  Eigen::MatrixXd Phi_rig;            ///< n x 6
  std::vector<Eigen::Matrix3d> Jinv;  ///< D's rotation blocks J_l^-1(theta_k) (D is 1 elsewhere)
  Eigen::Matrix<double, 6, 6> S, S_inv;
  Eigen::MatrixXd W;  ///< Phi_CB D (6 x n)
  Eigen::MatrixXd Z;  ///< 6 x n
  Eigen::MatrixXd T;  ///< n x n
  Eigen::MatrixXd B;  ///< n x n
};
/// The exact inertia's configuration-dependent products (has_exact_inertia).

/// The exact inertia's configuration-dependent products (has_exact_inertia).
struct ExactInertiaData {
  Eigen::MatrixXd Y;   ///< Phi_rig0 Z + B
  Eigen::MatrixXd H;   ///< n x 3: Gamma_a q
  Eigen::MatrixXd XQ;  ///< n x 9: Xi_ab q in column 3 a + b (Xi_ba = Xi_ab^T)
  Eigen::Matrix3d Xq;  ///< q^T Xi_ab q
  /// For the matrices only (ExactMass, ExactGyroscopic), made when first asked (has_products):
  /// M Y and H^T Y (3 x n).
  Eigen::MatrixXd MY, HtY;
  bool has_products = false;
  Eigen::VectorXd xq;  ///< scratch of Exact
};

/// Everything one configuration of the body determines, computed once (Evaluate) and passed to
/// every force, matrix and energy evaluated there: an assembly pass evaluates each body's
/// kinematics once instead of once per term (the model / data split). The body (the model) is
/// const; the kernels take the data by reference and leave in it what they computed for the
/// next kernel at the same configuration (the maps, the exact mass, the local force, the
/// stiffening's products, each with its flag, cleared by Evaluate) and their temporaries.
struct BodyData {
  BodyConfiguration c;
  FrameSolution frame;
  Eigen::VectorXd q;  ///< q_loc
  BodyKinematics kin;
  std::optional<ExactInertiaData> exact;  ///< with the exact inertia (kept: its storage reused)
  BodyVelocityMaps maps;                  ///< the corotational maps, made when first asked (has_maps)
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

/// What a body is: a superelement from its file, or a rigid body given by its mass, centre of
/// mass and inertia.
enum class BodyKind { kSuperelement, kRigid };

/// Immutable model of one body (a superelement from its file, or a rigid body) plus its placement
/// in the scene. The kernels read its data members; nothing changes them after the constructor
/// (the system model holds it const).
class SuperelementBody {
 public:
  /// `placement_R`, `placement_x` map part coordinates to global ones (x = p + R_p X).
  SuperelementBody(const Superelement& se, const SuperelementOptions& options,
                   const Eigen::Matrix3d& placement_R = Eigen::Matrix3d::Identity(),
                   const Eigen::Vector3d& placement_x = Eigen::Vector3d::Zero());
  /// A rigid body: one node at the centre of mass (its own frame: Phi_CB = 1) carrying the 6 x 6
  /// mass [m 1, 0; 0, J_com] in body axes, no stiffness, no modes. Body axes are the part axes of
  /// `p` placed by `placement_R`, `placement_x`.
  static SuperelementBody Rigid(const MassProperties& p, const Eigen::Matrix3d& placement_R,
                                const Eigen::Vector3d& placement_x);

  BodyKind kind() const { return kind_; }

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
  /// The undeformed configuration's floating frame.
  FrameSolution InitialFrame() const { return initial_frame_; }
  /// The coordinates the modal stresses are taken at: q_loc, or with the geometric stiffening's
  /// condensed polynomial its eps = q + K^+ A z (formats/reduced_polynomial.h).
  Eigen::VectorXd StressCoordinates(const Eigen::VectorXd& q) const {
    return polynomial_ ? femb::StressCoordinates(*polynomial_, q) : q;
  }
  /// Thesis 8.2 case 4: a basis that moves only m < 6N interface directions holds the others
  /// with the file's C q_int = 0 (formats/superelement.h interface_constraint; r rows, lengths).
  /// femb-solve adds it to the system with Lagrange multipliers (solver/joints/loop_constraints.h).
  int n_constraints() const { return int(C_.rows()); }
  /// True when the body uses the geometric stiffness of inertia load cases (file and option).
  bool has_inertia_stiffening() const { return !K_sigma_.empty(); }
  /// True when the body uses the exact kinetic energy (file invariants and option exact_inertia;
  /// solver/body/exact_inertia.h).
  bool has_exact_inertia() const { return !Gamma_.empty(); }
  /// The body's mass.
  double mass() const { return mass_; }
  /// The body's length: the farthest interface node from the frame origin, or for a one-node body
  /// its radius of gyration (the moments' lever in ForceNorm).
  double length() const { return length_; }

  // The model's data (set by the constructor, read by the kernels).
  BodyKind kind_ = BodyKind::kSuperelement;
  Eigen::MatrixXd Phi_rig0_;
  // CenterOfMass: the mass m, the undeformed first moment s_0 about the frame origin, and C.
  double mass_ = 0.0;
  double length_ = 1.0;  ///< length()
  Eigen::Vector3d first_moment0_ = Eigen::Vector3d::Zero();
  Eigen::MatrixXd first_moment_map_;    ///< 3 x n
  std::vector<Eigen::MatrixXd> Gamma_;  ///< the file's inertia invariants Gamma_a (3), or none
  // The invariants stacked for one matrix-vector product each: [Gamma_0; Gamma_1; Gamma_2]
  // (3n x n) and Xi_ab at row block 3 a + b (9n x n, Xi_ba = Xi_ab^T); Phi_rig0^T M (6 x n).
  Eigen::MatrixXd Gamma_stack_, Xi_stack_, PtM_;
  int n_nodes_ = 0, n_modes_ = 0;
  SuperelementOptions options_;
  Eigen::MatrixXd K_, M_, Phi_CB_;
  Eigen::MatrixXd C_;                              ///< interface constraint (r x 6N; no rows: none)
  std::optional<PolynomialStiffness> polynomial_;  ///< set when the file has it and the option is on
  std::vector<Eigen::MatrixXd> K_sigma_;           ///< the 12 inertia load case geometric stiffnesses, or none
  Eigen::MatrixXd K_sigma_stack_;                  ///< the same stacked (12n x n)
  std::vector<Eigen::Vector3d> X_;                 ///< node positions relative to the frame origin, frame axes
  std::vector<Eigen::Matrix3d> R0_;                ///< node orientations relative to the frame
  Eigen::MatrixXd T0_;                             ///< 1 - Phi_rig0 Phi_CB (approximated option)
  Eigen::Matrix3d placement_R_;
  Eigen::Vector3d placement_x_;
  Eigen::Vector3d origin_part_;
  FrameSolution initial_frame_;
  double force_floor_ = 0.0;
  double k_max_ = 0.0;  ///< max|D K D|, D = diag(force_weights_): force per length
  /// max|D K D| over the interface nodes' coordinates' columns: the stiffness through which the
  /// absolute positions' round-off reaches the forces (RoundOffForce). The modal coordinates are
  /// unknowns of their own, untouched by that round-off; with them, a body's stiffest mode would
  /// set the floor (a spinning bar: 2e4 times the residual's true noise).
  double k_nodes_max_ = 0.0;
  double m_max_ = 0.0;             ///< max|D M D|: force per acceleration
  Eigen::VectorXd force_weights_;  ///< see ForceNorm
  double modal_weight_ = 1.0;

 private:
  SuperelementBody() = default;  // (Rigid)
  // The constants derived from the matrices, the nodes and the placement: mass and first moment,
  // T0, the force weights and floor, the initial frame.
  void DeriveConstants();
};

}  // namespace femb
