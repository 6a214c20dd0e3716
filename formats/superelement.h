// The superelement: the only contract between femb-reduce and femb-solve (and femb-inspect).
// Written and read by superelement_file.h; the on-disk schema is in SUPERELEMENT_FORMAT.md.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "formats/reduced_polynomial.h"
#include "formats/vtk_cells.h"

namespace femb {

/// Unit system of every number in a part and its superelement. Consistent systems only:
/// force = mass * length / time^2, stress = force / length^2.
struct Units {
  std::string system = "SI";  ///< "SI" (m, kg, s), "mm-t-s" (mm, t, s) or "mm-kg-ms" (mm, kg, ms)
  std::string length = "m";
  std::string mass = "kg";
  std::string time = "s";
  std::string force = "N";
  std::string stress = "Pa";
  std::string angle = "rad";
};

/// One 6-DOF interface node: position in part axes [length]; orientation maps node axes to part
/// axes. Its reduced coordinates are (u_x, u_y, u_z, theta_x, theta_y, theta_z) in part axes.
struct InterfaceNode {
  std::string name;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Matrix3d orientation = Eigen::Matrix3d::Identity();
};

/// The floating frame: the point whose elastic deformation is zero, thesis (3.7):
/// Phi_CB * q = 0, with Phi_CB (6 x n_reduced) and Phi_CB * Phi_rig0 = 1, Phi_rig0 built from
/// the interface positions relative to `origin` (thesis 3.20).
struct FloatingFrame {
  std::string type;                                  ///< center_of_mass | mean_axes | interface:<name> | cardona
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  ///< undeformed, part axes [length]
  Eigen::Matrix3d orientation = Eigen::Matrix3d::Identity();  ///< frame axes in part axes
  Eigen::MatrixXd Phi_CB;                                     ///< 6 x n_reduced
  Eigen::VectorXd cardona_weights;                            ///< alpha_k (cardona only)
};

/// Rigid-body mass properties of the undeformed part (from the full FE mass matrix).
struct MassProperties {
  double mass = 0.0;                                         ///< [mass]
  Eigen::Vector3d center_of_mass = Eigen::Vector3d::Zero();  ///< part axes [length]
  Eigen::Matrix3d inertia_com = Eigen::Matrix3d::Zero();     ///< about the CoM, part axes [mass length^2]
};

/// Optional: the full mesh and each reduced coordinate's full displacement field, for
/// visualization and stress recovery.
struct Visualization {
  Eigen::MatrixXd nodes;  ///< n_nodes x 3, part axes [length]
  Eigen::MatrixXi cells;  ///< n_cells x nodes_per_cell, 0-based node indices
  CellType cell_type = CellType::kLine2;
  int dofs_per_node = 6;   ///< 6 (u, theta) for beams, 3 (u) for solids
  Eigen::MatrixXd shapes;  ///< (n_nodes * dofs_per_node) x n_reduced, node-major
  /// Per interface: the mesh nodes its coupling ties (a beam's interface: its own node); empty
  /// in files written before they were stored.
  std::vector<std::vector<int>> interface_nodes;
};

/// Optional: the stress that each reduced coordinate causes at stress points of the
/// kept mesh. Linear: sigma(point p) = sum_i q_i modes.block(6 p, i, 6, 1) for local coordinates
/// q (the rigid-body modes cause none). Components (xx, yy, zz, yz, xz, xy), Cauchy = linear
/// stress, part axes, [stress per unit of the coordinate]. Solids: one point per mesh node (the
/// element stresses at the quadrature points projected onto each element's own shape functions
/// (local L2 projection), averaged over the elements at the node weighted by their volume).
/// Beams: fibre points of the section at both ends of every element (axial stress from the
/// normal force and the bending moments, shear from torsion and transverse shear; see
/// reducer/reduction/modal_stress.h), several per mesh node.
struct ModalStress {
  std::string method;      ///< "solid_nodal_l2" or "beam_fibres": how the points were made
  Eigen::MatrixXd points;  ///< n_points x 3, part axes [length]
  Eigen::VectorXi node;    ///< n_points: the visualization mesh node each point belongs to
  Eigen::MatrixXf modes;   ///< (6 n_points) x n_reduced, point-major
  /// Beams: the section forces at the element ends, (12 n_cells) x n_reduced: per element
  /// (N, V_y, V_z, T, M_y, M_z) at its first node, then at its second, in element axes (the
  /// force and moment that the part beyond the cut exerts, i.e. tension and sagging positive as
  /// in beam theory); element_axes (n_cells x 9): rows e1 (along), e2, e3 of each element, part
  /// axes. Empty for solids.
  Eigen::MatrixXf section_forces;
  Eigen::MatrixXd element_axes;
  /// With geometric stiffening (the 12 unit inertia load cases, kInertiaLoadCases): the stress of
  /// each case's static field with the interfaces held, less its internal-mode part, (6 n_points)
  /// x 12, and for beams its section forces (12 n_cells) x 12. The body's stress is then
  /// sum_i q_i modes_i + sum_k a_k inertia_modes_k with the frame's load factors a_k
  /// (InertiaLoads, solver/body/inertia_stiffening.h): the quasi-static part of the distributed inertia load's
  /// stress that the basis does not carry (a mode-acceleration correction); empty otherwise.
  Eigen::MatrixXf inertia_modes;
  Eigen::MatrixXf inertia_section_forces;
  /// Solids with modal derivatives: each basis vector's displacement gradient H = du/dX at the
  /// points, (9 n_points) x n_reduced (row 9 p + 3 i + j: du_i/dX_j, part axes), and the
  /// material's E and nu. The stress is then the second Piola-Kirchhoff stress of St. Venant-
  /// Kirchhoff, S = D (E_lin + E_quad) with E_quad = H^T H / 2 (H = sum_i q_i H_i): the
  /// Green-Lagrange strain's linear and quadratic parts, as the body's polynomial force. Empty
  /// otherwise (linear stress).
  Eigen::MatrixXf gradients;
  /// Beams with modal derivatives: the von Karman part of the axial strain, element by element
  /// as in the body's polynomial force (reducer/fe/nonlinear_beam.h: the element mean of
  /// (v'^2 + w'^2) / 2), a quadratic form q^T Q_e q / 2 per element stored as its upper triangle
  /// row by row (n_cells x n (n + 1) / 2), and the element of each stress point (n_points); the
  /// stress adds E q^T Q_e q / 2 along the element axis. Empty otherwise.
  Eigen::MatrixXf element_quadratic;
  Eigen::VectorXi point_element;
  double E = 0.0, nu = 0.0;
  int n_points() const { return int(points.rows()); }
};

/// Where the file came from and what it cost.
struct Provenance {
  std::string femb_version;
  std::string input_file;
  std::string input_hash;  ///< FNV-1a 64-bit of the part file text, hex
  std::string element_type;
  std::string reduction_method;  ///< craig_bampton | free_interface ("" in files before it was stored)
  long n_nodes = 0;
  long n_elements = 0;
  std::vector<std::pair<std::string, double>> stage_seconds;
};

/// The unit inertia load cases of the inertia stiffening, in the order stored: the acceleration
/// fields (frame axes, positions x from the floating frame origin) a, alpha x x and the
/// centrifugal omega x (omega x x) split into the products of omega's components:
///   a_x a_y a_z | alpha_x alpha_y alpha_z | w_x^2 w_y^2 w_z^2 w_x w_y w_x w_z w_y w_z.
inline constexpr int kInertiaLoadCaseCount = 12;
inline constexpr const char* kInertiaLoadCases[kInertiaLoadCaseCount] = {
    "a_x", "a_y", "a_z", "alpha_x", "alpha_y", "alpha_z", "wx_wx", "wy_wy", "wz_wz", "wx_wy", "wx_wz", "wy_wz"};

struct Superelement {
  std::string name;
  Units units;
  std::vector<InterfaceNode> interfaces;
  /// Reduced stiffness and mass, n_reduced x n_reduced, ordered
  /// [node 1 (u, theta), ..., node N (u, theta), internal mode 1, ..., internal mode m].
  Eigen::MatrixXd K;
  Eigen::MatrixXd M;
  Eigen::VectorXd internal_frequencies_hz;  ///< fixed-interface frequencies of the internal modes
  FloatingFrame floating_frame;
  MassProperties mass_properties;
  long n_full_dofs = 0;
  Eigen::VectorXd full_free_free_frequencies_hz;  ///< optional (empty when not computed)
  /// The interfaces whose rigid (RBE2) couplings the unreduced model above includes: their node
  /// sets move rigidly, so its free-free frequencies are those of the part with those faces
  /// stiffened, not of the bare part (RBE3 couplings add no stiffness). Empty: none.
  std::vector<std::string> full_rigid_couplings;
  long n_modal_derivatives = 0;
  /// The reduced coordinates (i, j) whose shapes each modal derivative differentiates:
  /// theta = -K_ii^-1 (dK/dq_j) phi_i before deflation (n_modal_derivatives pairs).
  std::vector<std::pair<int, int>> modal_derivative_pairs;
  /// With modal derivatives: the quadratic and cubic coefficients of the reduced Green-Lagrange
  /// internal force (reduced_polynomial.h); the solver then uses it in place of K q.
  std::optional<PolynomialStiffness> polynomial;
  /// Geometric stiffening from rigid-body inertia loads (InertiaLoads, solver/body/inertia_stiffening.h):
  /// K_sigma,k = Phi^T G(sigma_k) Phi (n x n, symmetric) of the stress sigma_k of unit inertia
  /// load case k (kInertiaLoadCases) with the interfaces held; empty when not computed.
  std::vector<Eigen::MatrixXd> inertia_stiffness;
  /// Inertia invariants of the floating frame formulation (the SID of Wallrapp): with
  /// S_a the skew matrix of e_a on every translation and rotation triple of the full model (it
  /// turns a displacement field with the frame), Phi the full basis and M the full mass matrix,
  ///   inertia_gamma[a] = Gamma_a  = Phi^T M S_a Phi          (a = x, y, z)
  ///   inertia_xi[k]    = Xi_ab    = (S_a Phi)^T M (S_b Phi)  (ab = xx yy zz xy xz yz; Xi_ba = Xi_ab^T)
  /// (n x n each); empty when not computed. SuperelementBody uses them for the exact kinetic
  /// energy of the reduced field in the floating frame.
  std::vector<Eigen::MatrixXd> inertia_gamma, inertia_xi;
  /// A basis that moves only m < 6N interface directions (thesis 8.2, case 4; reduction.method
  /// general): C (r x 6N, r = 6N - m) with C q_int = 0 on the local interface coordinates of the
  /// floating frame (translations, rotations). Its rows have unit length after the rotation
  /// columns are divided by the part's size, so C q_int is a length. femb-solve enforces it with
  /// Lagrange multipliers (InterfaceConstraint, solver/body/elastic_force.h). No rows: none.
  Eigen::MatrixXd interface_constraint;
  std::optional<Visualization> visualization;
  std::optional<ModalStress> stress;  ///< only with the visualization mesh
  Provenance provenance;

  int n_interface_nodes() const { return int(interfaces.size()); }
  int n_interface_dofs() const { return 6 * n_interface_nodes(); }
  int n_internal_modes() const { return int(internal_frequencies_hz.size()); }
  int n_reduced_dofs() const { return int(K.rows()); }
};

/// What femb-solve's generalized-alpha integrator can do with the file's body, in one line:
/// its inertia (exact, from the inertia invariants, or corotational only) and its geometric
/// stiffening (inertia load cases, the basis's own stress, the cubic force of modal derivatives,
/// or none: linear inside), e.g. "exact inertia; geometric stiffening of the inertia loads and
/// the basis's stress".
std::string DynamicsSummary(const Superelement& se);

/// Label of reduced coordinate i, e.g. "A.u_x", "B.theta_z", "mode 3 (512.4 Hz)",
/// "derivative 2 (B.u_y x mode 1)".
std::string ReducedCoordinateLabel(const Superelement& se, int i);

/// Rigid-body modes of the interface coordinates about `origin` (thesis 3.20):
/// Phi_rig0 (n_reduced x 6), rows of the internal modes zero.
Eigen::MatrixXd RigidBodyModes(const Superelement& se, const Eigen::Vector3d& origin);
/// One node's block of them, [1, -x~; 0, 1] for the node at x from the origin (thesis 3.12).
Eigen::Matrix<double, 6, 6> NodeRigidBodyModes(const Eigen::Vector3d& x);

}  // namespace femb

namespace femb {

/// 6 x 6 rigid-body mass matrix about `origin` in part axes, thesis (3.21):
/// M_rig = Phi_rig0^T M Phi_rig0 = [m 1, -m c~; m c~, J_origin], c the CoM relative to origin.
Eigen::Matrix<double, 6, 6> RigidBodyMassMatrix(const Superelement& se, const Eigen::Vector3d& origin);

/// Mass, centre of mass and inertia about the centre of mass from the reduced mass matrix
/// (exact: the static modes reproduce rigid motions of the full model).
MassProperties ComputeMassProperties(const Superelement& se);

}  // namespace femb

namespace femb {
/// von Mises equivalent stress of (xx, yy, zz, yz, xz, xy).
double VonMises(const Eigen::Matrix<double, 6, 1>& s);
/// Principal stresses of (xx, yy, zz, yz, xz, xy), largest first.
Eigen::Vector3d PrincipalStresses(const Eigen::Matrix<double, 6, 1>& s);
/// The largest and the smallest principal stress, to about 1e-7 of the deviator's size (the
/// closed form of PrincipalStresses with the last trigonometry in single precision: the
/// animation's fields, stored to 2^-12 of a frame's largest).
Eigen::Vector2d ExtremePrincipalStresses(const Eigen::Matrix<double, 6, 1>& s);
/// The stress field of local coordinates q at the mesh nodes: per node the 6 components (xx, yy,
/// zz, yz, xz, xy; part axes) of its stress point with the largest von Mises stress (solids: its
/// only point; beams: the most stressed fibre of the sections at the node) in `stress`
/// (n_nodes x 6) and that von Mises stress in `von_mises` (n_nodes). Nodes without a point: 0.
/// `inertia`: the 12 inertia load factors of the body's frame, for the inertia load cases'
/// stresses (ModalStress::inertia_modes; ignored when the file has none or when null).
void NodeStresses(const ModalStress& modal, const Eigen::VectorXd& q, long n_nodes, Eigen::MatrixXd* stress,
                  Eigen::VectorXd* von_mises, const Eigen::VectorXd* inertia = nullptr,
                  Eigen::VectorXf* scratch = nullptr);
/// The stress (6 components) at stress point p of local coordinates q (and inertia factors).
Eigen::Matrix<double, 6, 1> PointStress(const ModalStress& modal, int p, const Eigen::VectorXd& q,
                                        const Eigen::VectorXd* inertia = nullptr);
/// Signed frequency in Hz from an eigenvalue omega^2: sign(lambda) sqrt(|lambda|) / (2 pi).
double FrequencyHz(double lambda);
}  // namespace femb
