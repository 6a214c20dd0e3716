// libFuzzer target: the part file parser on arbitrary text (seed corpus: the examples' part
// files). Bad input must end in an InputError; anything else is a bug.
#include <cstdint>
#include <string>

#include "formats/input_error.h"
#include "formats/part_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    (void)femb::ParsePart(text, "fuzz/part.yaml", {});
  } catch (const femb::InputError&) {
  }
  return 0;
}
