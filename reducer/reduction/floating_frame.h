// Floating frame choices (thesis 1.4, 3.7; Cardona 2000 eq. 14-22). Each gives the frame origin
// (undeformed) and Phi_CB (6 x n_r) with Phi_CB * Phi_rig0 = 1, Phi_rig0 about that origin:
//   center_of_mass   the material point at the undeformed centre of mass: Phi_CB = N(x_c) Phi,
//                    N the element interpolation there, Phi the full shapes of the reduced
//                    coordinates. Refused when x_c lies outside the material.
//   mean_axes        origin x_c, Phi_CB = M_rig^-1 Phi_rig0^T M_r (linearized Tisserand frame:
//                    no momentum of the deformation relative to the frame).
//   interface:<name> the interface node's frame: Phi_CB selects its 6 coordinates.
//   cardona          origin sum_k alpha_k x_k, Phi_CB = [alpha_1 1, ..., alpha_N 1, 0] with
//                    alpha = pinv(A) v, A = [X^T X; e^T], v = [X^T x_c; 1] (Cardona eq. 21-22);
//                    X holds the interface positions relative to x_c.
#pragma once

#include <string>

#include "formats/part_file.h"
#include "formats/superelement.h"
#include "reducer/fe/fe_model.h"

namespace femb {

/// The frame `reduction` asks for (floating_frame, floating_frame_interface; messages name
/// where_floating_frame). `se` must have interfaces, K, M and mass_properties set; `shapes` is
/// n_full x n_r (held as CraigBamptonResult::shapes: on MPI ranks this rank's rows). Throws InputError for
/// center_of_mass outside the material.
FloatingFrame ComputeFloatingFrame(const ReductionSpec& reduction, const Superelement& se, const FeModel& model,
                                   const Eigen::MatrixXd& shapes);

/// The refusals of `type` that need only the model's mesh and mass, before any reduction work:
/// center_of_mass without volume cells or with the centre of mass (from the full M and the rigid
/// fields) outside the material. Throws the same InputError as ComputeFloatingFrame.
void CheckFloatingFrame(const ReductionSpec& reduction, const FeModel& model);

}  // namespace femb
