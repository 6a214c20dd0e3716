// Modal stresses: the linear stress that each reduced basis vector causes in the part,
// for stress recovery in femb-solve (sigma(t) = sum_i q_loc,i(t) sigma_i) and for femb-inspect.
//
// Solids: sigma = D B u at every quadrature point of every element (the element's own rule,
// solid_element.h), projected onto the element's shape functions (local L2 projection: nodal
// values s_a = sum_b (M_e^-1)_ab int N_b sigma dV with M_e = int N N^T dV, exact for a stress
// field the shape functions can represent; for HEX8 with its 2^3 rule it is the classical
// extrapolation from the Gauss points), then averaged over the elements sharing a node, weighted
// by their volume. Components xx, yy, zz, yz, xz, xy in part axes.
//
// Beams: the section forces at both ends of every element from its local stiffness,
// f = K_e T u_e (timoshenko_beam.h; exact for end-loaded elements), N, V_y, V_z, T, M_y, M_z
// positive as in beam theory (the force of the part beyond the cut on the cut face whose outer
// normal is +x), and at fibre points of the named sections the stress they cause:
//   sigma_xx = N / A + M_y z / I_y - M_z y / I_z           (the element's sign convention: the
//                                                            axial strain is u' + z th_y' - y th_z')
//   torsion: circle and tube tau = T rho / J (tangential); rectangle (half sides a >= b) Saint-
//     Venant's series solution (Timoshenko and Goodier, Theory of Elasticity, sec. 109): with
//     G theta = T / [(16/3) a b^3 (1 - (192 / pi^5)(b / a) sum_n tanh(n pi a / 2b) / n^5)],
//     tau = 2 G theta b - (16 G theta b / pi^2) sum_n sech(n pi a / 2b) / n^2 at the middle of the
//     long sides and (16 G theta b / pi^2) sum_n (-1)^((n-1)/2) tanh(n pi a / 2b) / n^2 at the
//     middle of the short sides (n odd), zero at the corners;
//   transverse shear (Jourawski) at the neutral axis of each shear force: rectangle 3 V / (2 A),
//     circle 4 V / (3 A), tube (4/3)(V / A)(R^2 + R r + r^2) / (R^2 + r^2).
// Fibre points: circle and tube 8 points on the outer radius (every 45 degrees from +y),
// rectangle its 4 corners and the middles of its 4 sides. General sections (given A, I, J only)
// have no shape: their elements get section forces but no fibre points.
#pragma once

#include <Eigen/Core>

#include "formats/part_file.h"
#include "formats/superelement.h"
#include "reducer/fe/fe_model.h"
#include "reducer/fe/solid_element.h"
#include "reducer/fe/solid_ranks.h"

namespace femb {

/// Modal stresses of a solid part: `mesh_shapes` (3 n_nodes x n, node-major) the full
/// displacement field of each basis vector on the mesh `nodes` (n_nodes x 3), `cells` of `type`.
/// `gradients` (parts with modal derivatives): also each basis vector's displacement gradient at
/// the nodes, projected the same way, for the quadratic part of the Green-Lagrange strain
/// (ModalStress::gradients).
ModalStress SolidModalStress(SolidType type, const Eigen::MatrixXd& nodes, const Eigen::MatrixXi& cells,
                             const MaterialSpec& material, const Eigen::MatrixXd& mesh_shapes, bool gradients = false);

/// The same on the MPI ranks of a distributed reduction: each rank takes its own cells (`mesh`,
/// RankMesh; `mesh_fields` on its nodes), a node's sums are added on its owner (RankMesh::owner),
/// which divides them, and rank 0 gathers them: the whole result on rank 0 (`points` the whole
/// mesh's nodes), none (no points, 0-row stresses) on the others.
ModalStress SolidModalStressOnRanks(SolidType type, const Eigen::MatrixXd& points, const RankMesh& mesh,
                                    const MaterialSpec& material, const Eigen::MatrixXd& mesh_fields,
                                    bool gradients = false);

/// Modal stresses of a beam part: `shapes` (6 n_nodes x n) on the nodes of BeamElements(part).
/// `quadratic` (parts with modal derivatives): also the element quadratic forms of the von Karman
/// axial strain (ModalStress::element_quadratic).
ModalStress BeamModalStress(const PartSpec& part, const Eigen::MatrixXd& shapes, bool quadratic = false);

}  // namespace femb
