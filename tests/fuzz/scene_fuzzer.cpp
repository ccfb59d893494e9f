// libFuzzer target for the scene loader: any bytes either load as a scene or raise InputError.
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/error.h"
#include "scene/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    kf::parse_scene(std::string(reinterpret_cast<const char*>(data), size), "fuzz.json");
  } catch (const kf::InputError&) {
    // The expected outcome for malformed input; anything else escapes and is a finding.
  }
  return 0;
}
