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
// Throws InputError when the file is missing or not a PNG. Returns RGB or RGBA.
Image read_png(const std::filesystem::path& path);

}  // namespace kf::render
