#pragma once
// PNG files through libpng: 8-bit RGB or RGBA, written atomically.
#include <cstdint>
#include <filesystem>
#include <vector>

namespace kf::render {

struct Image {
  int width = 0, height = 0, channels = 3;  // 3 = RGB, 4 = RGBA
  std::vector<uint8_t> pixels;              // row-major, top row first
  Image() = default;
  Image(int w, int h, int c = 3) : width(w), height(h), channels(c), pixels(size_t(w) * h * c, 0) {}
  uint8_t* at(int x, int y) { return &pixels[(size_t(y) * width + x) * channels]; }
  const uint8_t* at(int x, int y) const { return &pixels[(size_t(y) * width + x) * channels]; }
};

// Throws OutputError when the file cannot be written; nothing is left behind.
void write_png(const std::filesystem::path& path, const Image& image);
// The largest PNG keyframe reads: 16384 pixels a side, 8192 x 8192 pixels in all (256 MiB as RGBA).
constexpr uint32_t kMaxPngSide = 16384;
constexpr uint64_t kMaxPngPixels = uint64_t(8192) * 8192;

struct PngHeader {
  int width = 0, height = 0;
};

// Throws InputError when the file is missing, not a PNG, or larger than the limits above (checked on the
// header, before anything is allocated). Returns RGB, or RGBA when the file has alpha or a transparent
// colour; interlaced (Adam7) files are assembled.
Image read_png(const std::filesystem::path& path);
// The size from the header alone (same checks as read_png up to the pixels).
PngHeader read_png_header(const std::filesystem::path& path);

}  // namespace kf::render
