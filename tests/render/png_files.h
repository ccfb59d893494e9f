#pragma once
// PNG files other tools write (interlaced) or that lie about their size, for the PNG reader's tests.
#include <gtest/gtest.h>
#include <png.h>
#include <zlib.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "render/image/png_io.h"
#include "synthetic_runs.h"

namespace kf::render {

// Writes `img` as an interlaced (Adam7) PNG, the way other tools may save frames.
inline void write_interlaced_png(const std::filesystem::path& path, const Image& img) {
  FILE* f = std::fopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  png_init_io(png, f);
  png_set_IHDR(png, info, img.width, img.height, 8, img.channels == 4 ? PNG_COLOR_TYPE_RGBA : PNG_COLOR_TYPE_RGB,
               PNG_INTERLACE_ADAM7, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  std::vector<png_bytep> rows;
  for (int y = 0; y < img.height; ++y) rows.push_back(const_cast<png_bytep>(img.at(0, y)));
  png_write_image(png, rows.data());
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  std::fclose(f);
}

// A PNG whose IHDR claims `width` x `height` RGB pixels followed by one IDAT of a single row's worth at
// most: the size is a lie a decoder finds only after allocating for it.
inline void write_header_only_png(const std::filesystem::path& path, uint32_t width, uint32_t height) {
  std::string bytes = "\x89PNG\r\n\x1a\n";
  auto chunk = [&](const char* type, const std::string& data) {
    auto be32 = [&](uint32_t v) {
      for (int k = 3; k >= 0; --k) bytes += char((v >> (8 * k)) & 0xff);
    };
    be32(uint32_t(data.size()));
    const std::string body = std::string(type, 4) + data;
    bytes += body;
    be32(uint32_t(crc32(0, reinterpret_cast<const Bytef*>(body.data()), uInt(body.size()))));
  };
  std::string ihdr;
  for (uint32_t v : {width, height})
    for (int k = 3; k >= 0; --k) ihdr += char((v >> (8 * k)) & 0xff);
  ihdr += std::string("\x08\x02\x00\x00\x00", 5);  // 8 bits, RGB, deflate, adaptive filter, no interlace
  chunk("IHDR", ihdr);
  const std::string row(4, '\0');
  std::string packed(64, '\0');
  uLongf packed_size = uLongf(packed.size());
  compress(reinterpret_cast<Bytef*>(packed.data()), &packed_size, reinterpret_cast<const Bytef*>(row.data()), uLong(row.size()));
  chunk("IDAT", packed.substr(0, packed_size));
  chunk("IEND", "");
  testing::write_text(path, bytes);
}

}  // namespace kf::render
