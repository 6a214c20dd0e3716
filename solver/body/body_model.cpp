// The body model from a superelement file or a rigid body's inertia: the matrices, invariants and
// constants the kernels read.
#include "solver/body/body_model.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "formats/input_error.h"
#include "solver/body/superelement_body.h"
#include "solver/rotation.h"

namespace femb {

SuperelementBody::SuperelementBody(const Superelement& se, const SuperelementOptions& options,
                                   const Eigen::Matrix3d& placement_R, const Eigen::Vector3d& placement_x)
    : n_nodes_(se.n_interface_nodes()),
      n_modes_(se.n_reduced_dofs() - se.n_interface_dofs()),
      options_(options),
      K_(se.K),
      M_(se.M),
      Phi_CB_(se.floating_frame.Phi_CB),
      C_(se.interface_constraint.rows() > 0 ? se.interface_constraint : Eigen::MatrixXd(0, 6 * se.n_interface_nodes())),
      placement_R_(placement_R),
      placement_x_(placement_x),
      origin_part_(se.floating_frame.origin) {
  if (!se.floating_frame.orientation.isIdentity(1e-12)) {
    throw InputError(se.name + ": floating frame orientation other than the part axes is not supported");
  }
  for (const InterfaceNode& node : se.interfaces) {
    X_.push_back(node.position - se.floating_frame.origin);
    R0_.push_back(node.orientation);
  }
  Phi_rig0_ = RigidBodyModes(se, se.floating_frame.origin);
  DeriveConstants();
  // A file's polynomial is the modal derivatives' cubic force (option polynomial_force) or,
  // without derivatives, the geometric stiffening's quadratic force (option geometric_stiffening).
  if (se.polynomial && (se.polynomial->cubic() ? options_.polynomial_force : options_.geometric_stiffening)) {
    polynomial_ = WithCondensation(K_, *se.polynomial);
  }
  const int n = n_coordinates();
  if (options_.geometric_stiffening) {
    K_sigma_ = se.inertia_stiffness;
    if (!K_sigma_.empty()) {
      K_sigma_stack_.resize(kInertiaLoadCaseCount * n, n);
      for (int k = 0; k < kInertiaLoadCaseCount; ++k) K_sigma_stack_.middleRows(k * n, n) = K_sigma_[size_t(k)];
    }
  }
  if (options_.exact_inertia && se.inertia_gamma.size() == 3 && se.inertia_xi.size() == 6) {
    // Cardona's options are two forms of the corotational inertia; the exact kinetic energy has
    // one, whose frame-turning terms (the maps and sources of the midpoint scheme) are option A's.
    options_.cardona_option_b = false;
    Gamma_ = se.inertia_gamma;
    Gamma_stack_.resize(3 * n, n);
    for (int a = 0; a < 3; ++a) Gamma_stack_.middleRows(a * n, n) = Gamma_[size_t(a)];
    const int stored[3][3] = {{0, 3, 4}, {3, 1, 5}, {4, 5, 2}};  // xx yy zz xy xz yz
    Xi_stack_.resize(9 * n, n);
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        const Eigen::MatrixXd& X = se.inertia_xi[size_t(stored[a][b])];
        if (a <= b) {
          Xi_stack_.middleRows((3 * a + b) * n, n) = X;
        } else {
          Xi_stack_.middleRows((3 * a + b) * n, n) = X.transpose();
        }
      }
    PtM_ = Phi_rig0_.transpose() * M_;
  }
}

SuperelementBody SuperelementBody::Rigid(const MassProperties& p, const Eigen::Matrix3d& placement_R,
                                         const Eigen::Vector3d& placement_x) {
  SuperelementBody body;
  body.kind_ = BodyKind::kRigid;
  body.n_nodes_ = 1;
  body.n_modes_ = 0;
  body.K_ = Eigen::MatrixXd::Zero(6, 6);
  body.M_ = Eigen::MatrixXd::Zero(6, 6);
  body.M_.topLeftCorner(3, 3) = p.mass * Eigen::Matrix3d::Identity();
  body.M_.bottomRightCorner(3, 3) = p.inertia_com;
  body.Phi_CB_ = Eigen::MatrixXd::Identity(6, 6);  // the frame is the node's
  body.C_ = Eigen::MatrixXd(0, 6);
  body.placement_R_ = placement_R;
  body.placement_x_ = placement_x;
  body.origin_part_ = p.center_of_mass;
  body.X_ = {Eigen::Vector3d::Zero()};
  body.R0_ = {Eigen::Matrix3d::Identity()};
  body.Phi_rig0_ = NodeRigidBodyModes(Eigen::Vector3d::Zero());  // the node at the frame origin
  body.DeriveConstants();
  return body;
}

void SuperelementBody::DeriveConstants() {
  {
    // CenterOfMass's constants. Phi_rig0^T M Phi_rig0 = [m 1, -s~; s~, J]: the first moment s
    // from its (translation, rotation) block -s~ (entry (b, 3 + a) = e_b . (e_a x s)).
    const Eigen::MatrixXd MPhi = M_ * Phi_rig0_;
    const Eigen::Matrix<double, 6, 6> M_rig = Phi_rig0_.transpose() * MPhi;
    mass_ = M_rig(0, 0);
    first_moment0_ = Eigen::Vector3d(-M_rig(2, 4), -M_rig(0, 5), -M_rig(1, 3));
    first_moment_map_ = MPhi.leftCols<3>().transpose();
  }
  T0_ = Eigen::MatrixXd::Identity(n_coordinates(), n_coordinates()) - Phi_rig0_ * Phi_CB_;
  double size = 0.0;
  for (const Eigen::Vector3d& X : X_) size = std::max(size, X.norm());
  // Force units in any unit system (ForceNorm): moments over a length of the body (its size, or
  // for a one-node body its radius of gyration), modal forces times sqrt(mass).
  const double mass = (Phi_rig0_.col(0).transpose() * M_ * Phi_rig0_.col(0))(0, 0);
  const Eigen::Matrix<double, 6, 6> M_rig = Phi_rig0_.transpose() * M_ * Phi_rig0_;
  const double gyration = mass > 0 ? std::sqrt(M_rig.bottomRightCorner<3, 3>().diagonal().maxCoeff() / mass) : 0.0;
  const double length = size > 0 ? size : (gyration > 0 ? gyration : 1.0);
  length_ = length;
  force_weights_ = Eigen::VectorXd::Ones(n_coordinates());
  for (int k = 0; k < n_nodes_; ++k) force_weights_.segment<3>(6 * k + 3).setConstant(1.0 / length);
  modal_weight_ = std::sqrt(std::max(mass, 0.0));
  force_weights_.tail(n_modes_).setConstant(modal_weight_);
  k_max_ = (force_weights_.asDiagonal() * K_ * force_weights_.asDiagonal()).cwiseAbs().maxCoeff();
  m_max_ = (force_weights_.asDiagonal() * M_ * force_weights_.asDiagonal()).cwiseAbs().maxCoeff();
  // (the node coordinates' columns, every row: a basis other than Craig-Bampton's couples them
  // to the modal rows)
  const int n_node_coordinates = 6 * n_nodes_;
  k_nodes_max_ = n_node_coordinates == 0 ? 0.0
                                         : (force_weights_.asDiagonal() * K_.leftCols(n_node_coordinates) *
                                            force_weights_.head(n_node_coordinates).asDiagonal())
                                               .cwiseAbs()
                                               .maxCoeff();
  force_floor_ = 1e-4 * k_max_ * length;
  initial_frame_.x = placement_x_ + placement_R_ * origin_part_;
  initial_frame_.R = placement_R_;
  initial_frame_.ok = true;
}

}  // namespace femb
