// Diagnosis of a singular system matrix (static tangent, dynamic iteration matrix): which free
// motion it has, in the user's words ("node n1: translation along y, rotation about z").
#pragma once

#include <string>

#include "solver/assembly/system.h"

namespace femb {

/// Looks for a null vector of S restricted to the coordinates solved for. S is first scaled
/// symmetrically to unit diagonal, s_ij / sqrt(|s_ii s_jj|) (units of translations, rotations and
/// modal coordinates, and stiffness contrasts, then do not count); it is singular when its
/// smallest singular value is below 1e-13 of the largest. Returns "" for a regular matrix, else a
/// sentence naming the motion: the nodes with the largest parts of the null vector (rotations
/// weighted by the size of the model so that they compare with translations), the modal
/// coordinates that take part, and the likely cause. Dense SVD: up to 3000 free coordinates;
/// above, returns a sentence saying the matrix is singular without the motion.
std::string DescribeSingular(const SystemModel& model, const DofMap& dofs, const SystemState& state,
                             const SystemMatrix& S);

}  // namespace femb
