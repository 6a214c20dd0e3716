// The state a run reached, kept beside its results (OUTDIR/checkpoint.h5) so that another
// analysis can start from it (the scene's initial_state: {from: OUTDIR}): every node's placement
// and joint coordinates, the bodies' modal coordinates and floating frames, the multipliers, the
// velocities and accelerations over the unknowns, the time and the works done so far. Written
// with the results during the run and at its end (whole, under a temporary name, then renamed).
// The file names the model it belongs to (ModelSignature): a state is only read into the same
// bodies (superelement files compared by content), nodes, joints and cut joints.
#pragma once

#include <functional>
#include <string>

#include "formats/hdf5_file.h"
#include "solver/analysis/dynamic_analysis.h"
#include "solver/scene/scene_builder.h"

namespace femb {

/// One line per body (name, superelement file's content hash, coordinates), node (name, its
/// coordinates' count), joint and cut joint: what a state must be read into.
std::string ModelSignature(const Scene& scene);

/// Writes `state` (analysis "static" or "dynamic"; a static state has no velocities) as
/// `directory`/checkpoint.h5. `signature`: ModelSignature(scene), computed once per run. With
/// `resume` (captured at `state`) the file also holds what a dynamic run carries into its next
/// step (group /resume), and `extra` adds the caller's own groups (the results so far).
void WriteCheckpoint(const std::string& directory, const Scene& scene, const std::string& signature,
                     const DynamicState& state, AnalysisType analysis, const DynamicResume* resume = nullptr,
                     const std::function<void(h5::Writer&)>& extra = nullptr);

/// The state in `directory`/checkpoint.h5 for `scene`'s model, with its node Jacobians. Throws
/// InputError (one line naming the file) when there is none, it is not a femb checkpoint, is
/// truncated, or belongs to another model than `signature` (ModelSignature(scene); the first
/// difference named). `analysis`: the kind of run that wrote it.
DynamicState ReadCheckpoint(const std::string& directory, const Scene& scene, const std::string& signature,
                            AnalysisType* analysis = nullptr);

/// The checkpoint's /resume group (ReadCheckpoint's checks first), the state included, to the
/// bit; false when the checkpoint has none (a static run's, or one written before the first step).
bool ReadResume(const std::string& directory, const Scene& scene, const std::string& signature, DynamicResume& resume);

}  // namespace femb
