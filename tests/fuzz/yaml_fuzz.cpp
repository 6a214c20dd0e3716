// libFuzzer target: the YAML reader and its --set overrides on arbitrary text. Any outcome but
// a return or an InputError (a crash, a hang, another exception) is a bug.
#include <cstdint>
#include <string>

#include "formats/input_error.h"
#include "formats/yaml_reader.h"

namespace {

// Walks every value as every type: the accessors must throw InputError or answer.
void Walk(const femb::YamlValue& v, int depth) {
  if (depth > 64) return;
  try {
    (void)v.Number();
  } catch (const femb::InputError&) {
  }
  try {
    (void)v.Integer();
  } catch (const femb::InputError&) {
  }
  try {
    (void)v.Bool();
  } catch (const femb::InputError&) {
  }
  try {
    (void)v.String();
  } catch (const femb::InputError&) {
  }
  try {
    (void)v.Vector3();
  } catch (const femb::InputError&) {
  }
  try {
    for (const auto& [key, child] : v.Map().Entries()) Walk(child, depth + 1);
  } catch (const femb::InputError&) {
  }
  try {
    for (const femb::YamlValue& child : v.List()) Walk(child, depth + 1);
  } catch (const femb::InputError&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  // The first line, when it looks like one, is an override "key.path=value".
  const size_t newline = text.find('\n');
  const std::string first = text.substr(0, newline);
  try {
    femb::YamlDocument doc = femb::YamlDocument::LoadString(text, "fuzz.yaml");
    if (first.find('=') != std::string::npos && first.size() < 200) {
      try {
        doc.Set(first);
      } catch (const femb::InputError&) {
      }
    }
    Walk(doc.Root().AsValue(), 0);
  } catch (const femb::InputError&) {
  }
  return 0;
}
