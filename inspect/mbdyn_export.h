// A superelement as MBDyn's modal element reads it: the ASCII ".fem" file of the modal joint
// (MBDyn input manual, "Modal element"; record groups as MBDyn's struct/modal.cc parses them).
//
// femb's reduced model q (interface (u, theta) in part axes, then internal modes) moves with its
// floating frame, thesis (3.7): q = Phi_rig0 r + E eta with Phi_CB E = 0, so MBDyn's modal node
// is femb's floating frame (its origin and axes) and MBDyn's modal coordinates are eta. E spans
// the null space of Phi_CB; its columns solve E^T K E v = lambda E^T M E v on that space (modal
// mass ~ 1, modal stiffness ~ diag(omega^2), written as computed). In frame axes, with t_a and r_a
// the rigid translation and rotation columns of Phi_rig0 about the frame origin and Gamma_a,
// Xi_ab the file's inertia invariants turned to frame axes, the records are:
//   1 header (REV0, nodes, modes, 0, 0, 0)     2 node labels (interface names; mesh nodes 1..n)
//   5-7 node x, y, z relative to the frame origin   8 mode shapes, 6 per node (u, theta)
//   9 E^T M E   10 E^T K E   12 mass, centre of mass, inertia about it
//   14 Inv3 = t_a^T M E (3 x N)     15 Inv4 = r_a^T M E (3 x N)
//   16 Inv8_j(a, b) = r_a^T Gamma_b E_j    17 Inv5_jk(a) = (E^T Gamma_a E)(k, j)
//   18 Inv9_jk(a, b) = -(E^T Xi_ab E)(j, k)
// which are the consistent-mass forms of MBDyn's invariants (its lumped sums m_i phi_i,
// m_i x_i ~ phi_i, m_i phi_j ~ phi_k, -m_i x_i ~ phi_j ~, m_i phi_j ~ phi_k ~).
#pragma once

#include <string>
#include <vector>

#include "formats/superelement.h"

namespace femb {

struct MbdynExport {
  int modes = 0;
  int nodes = 0;
  std::vector<std::string> labels;  ///< the FEM node labels, interfaces first
  bool invariants = false;          ///< records 14-18 written (the file had the inertia invariants)
  std::vector<std::string> notes;   ///< what MBDyn's linear modal element does not carry
};

/// Writes `path` (to a temporary name, then renamed). With `mesh_nodes` and a mesh in the file,
/// every mesh node is a FEM node too (for MBDyn's output); the interfaces always are. Throws
/// InputError for a basis that moves only some interface directions (interface_constraint) and
/// when `path` cannot be written.
MbdynExport WriteMbdynFem(const Superelement& se, const std::string& path, bool mesh_nodes);

}  // namespace femb
