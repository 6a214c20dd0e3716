// libFuzzer target: the scene parser and the scene builder (bodies, joints, the joint graph,
// loads) on arbitrary text (seed corpus: the examples' scenes). The scene is read as if it lay
// in $FEMB_FUZZ_DIR, where fuzz.sh puts a valid superelement 'seg.h5' (interfaces A, B) so that
// scenes naming it get past loading. Bad input must end in an InputError.
#include <cstdint>
#include <cstdlib>
#include <string>

#include "formats/input_error.h"
#include "formats/scene_file.h"
#include "solver/assembly/system.h"
#include "solver/scene/scene_builder.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const char* dir = std::getenv("FEMB_FUZZ_DIR");
  const std::string name = std::string(dir ? dir : ".") + "/scene.yaml";
  try {
    const femb::SceneSpec spec = femb::ParseScene(text, name, {});
    const femb::Scene scene = femb::BuildScene(spec);
    const femb::DofMap dofs(scene.model);
    femb::SystemState state = femb::InitialState(scene.model);
    (void)dofs.n_dofs();
  } catch (const femb::InputError&) {
  }
  return 0;
}
