// What a scene's outputs refer to, resolved on the built model (BuildScene's last stages).
#pragma once

#include "formats/scene_file.h"
#include "solver/scene/scene_builder.h"

namespace femb {

// Point probes: the material point of the body at the probe's point (scene coordinates at the
// initial placement, i.e. part axes through the body's placement), interpolated in the cell of
// the file's mesh that holds it or, within the mesh size outside every cell, at the nearest mesh
// node; the stress at the body's stress point nearest to it. Effort probes: the prescribed
// coordinates of the node's joint.
void ResolveProbes(const SceneSpec& spec, Scene& scene);

/// outputs.stress_exclude: per body with stresses, the mesh nodes within the distance of the
/// nodes the named interfaces' couplings tie (Scene::stress_excluded), with a note per body.
void ResolveStressExclusion(const SceneSpec& spec, Scene& scene);

}  // namespace femb
