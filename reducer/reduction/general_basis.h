// A superelement from a general set of deformation shapes (thesis 8.2, eqs. 8.10-8.20): any
// basis V (n_dofs x M) of the part's model - free-interface normal modes, residual attachment
// modes, shapes from another code - brought to the form femb-solve uses, the 6N interface
// coordinates of the absolute interface formulation plus internal coordinates (8.2):
//   q_i = Phi_i q + Psi_i eta.
// The construction:
//  1. rigid-body fields are appended (8.2's requirement that the shapes describe rigid motion)
//     and the set is M-orthonormalized, dependent columns dropped (eigenvalues of V^T M V below
//     1e-10 of the largest);
//  2. Phi_IP = B V (8.12), B the interface coordinates (the interface DOFs for RBE2, the RBE3
//     weights W); its SVD gives the rank m of the interface span:
//       m = 6N, M = 6N: Phi_IP is invertible, Phi = V Phi_IP^-1 (case 2);
//       m = 6N, M > 6N: Psi0 = V N, N the null space of Phi_IP (the M - 6N shapes with no motion at
//         the interfaces, eq. 8.20), Phi0 = V Phi_IP^+ (8.13) (case 3);
//       m < 6N: the shapes cannot move 6N - m interface directions (case 4). The thesis: "the
//         local interface coordinates should be constrained such that this subspace is
//         suppressed". The SVD is taken of L Phi_IP (rotation rows times the part's size L, so
//         that every row is a length); its left singular vectors past the rank, U_2, give the
//         constraint C q_int = 0 with C = E L (r x 6N, r = 6N - m; E the reduced row echelon
//         form of U_2^T with unit rows, so that each row involves few coordinates), stored in the file for femb-solve
//         to enforce with multipliers (InterfaceConstraint, solver/body/elastic_force.h). Phi0 = V (L Phi_IP)^+ L moves
//         the spanned directions; the constrained ones get the static constraint modes' field Psi_c L^-1 U_2 U_2^T L
//         (when `static_modes` are given; else none): it never deforms the body (the constraint holds their coordinates
//         at zero) but keeps K and M regular outside the constraint, so that every check and analysis of a file applies
//         unchanged;
//  3. Phi is condensed within the basis, Phi = Phi0 - Psi0 (Psi0^T K Psi0)^-1 Psi0^T K Phi0: the
//     least-strain-energy field of span V for each unit interface motion. The pseudo-inverse of
//     (8.13) is one of many right inverses of Phi_IP; this one reproduces rigid-body motions
//     exactly (they cost no energy and lie in span V), which the floating frame formulation needs
//     (Phi_rig0 with no internal part), and makes K_r block-diagonal as in Craig-Bampton;
//  4. Psi0 is rotated to the eigenvectors of (Psi0^T K Psi0, Psi0^T M Psi0): internal
//     coordinates with K = diag(lambda), M = 1 on their block, lambda the basis's
//     fixed-interface eigenvalues (stored as the internal frequencies).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "reducer/fe/fe_model.h"

namespace femb {

struct GeneralBasisResult {
  bool ok = false;
  std::string message;                      ///< why not (input: an unspanned interface direction; or numerical)
  bool input_error = false;                 ///< the shapes cannot serve as a basis (case 4, or no internal stiffness)
  Eigen::MatrixXd shapes;                   ///< n_dofs x (6N + k): [Phi, Psi]
  Eigen::MatrixXd K, M;                     ///< reduced
  Eigen::VectorXd lambda;                   ///< internal eigenvalues, ascending
  int columns_given = 0, columns_kept = 0;  ///< of V (+ rigid fields), after dropping dependent ones
  int interface_rank = 0;                   ///< m
  /// Case 4 (m < 6N): C (r x 6N) with C q_int = 0 on the local interface coordinates; no rows
  /// otherwise. L: the size that scales its rotation columns (C q_int is a length).
  Eigen::MatrixXd interface_constraint;
  double constraint_length = 1.0;
  /// Case 4: for each constraint row, the interface coordinates (6 k + d) it weighs at least
  /// half as much as its largest (lengths: rotations times L), largest first.
  std::vector<std::vector<int>> constraint_direction;
};

/// The interface coordinates as rows acting on model DOFs (6N x n_dofs): RBE2 DOFs and RBE3 W.
SparseMatrix InterfaceRows(const FeModel& model);

/// `static_modes`: the Craig-Bampton static constraint modes (n_dofs x 6N), for case 4's
/// constrained directions (nullptr: those directions get no field, K and M are singular there).
GeneralBasisResult ReduceOnGeneralBasis(const FeModel& model, const Eigen::MatrixXd& V,
                                        const Eigen::MatrixXd* static_modes = nullptr);

}  // namespace femb
