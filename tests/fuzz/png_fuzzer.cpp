// libFuzzer target for the PNG reader: any bytes either decode (within the size limit) or raise
// InputError; a crash, a leak, an allocation past the limit or another exception is a finding.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.h"
#include "render/image/png_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  namespace fs = std::filesystem;
  static const fs::path file = fs::temp_directory_path() / ("keyframe_png_fuzz_" + std::to_string(::getpid()) + ".png");
  std::ofstream(file, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data), std::streamsize(size));
  try {
    const kf::render::PngHeader h = kf::render::read_png_header(file);
    const kf::render::Image img = kf::render::read_png(file);
    if (img.width != h.width || img.height != h.height || (img.channels != 3 && img.channels != 4) ||
        img.pixels.size() != size_t(img.width) * img.height * img.channels)
      __builtin_trap();  // the header and the pixels disagree
  } catch (const kf::InputError&) {
  }
  return 0;
}
