#include <gtest/gtest.h>

#include <functional>

#include "core/error.h"
#include "render/image/png_io.h"
#include "png_files.h"
#include "synthetic_runs.h"

namespace kf::render {

TEST(PngIo, RoundTripsRgbAndRgba) {
  testing::TempDir tmp;
  for (int channels : {3, 4}) {
    Image img(37, 23, channels);
    for (size_t i = 0; i < img.pixels.size(); ++i) img.pixels[i] = uint8_t((i * 131 + 7) % 256);
    const auto path = tmp.path() / ("img" + std::to_string(channels) + ".png");
    write_png(path, img);
    const Image back = read_png(path);
    EXPECT_EQ(back.width, 37);
    EXPECT_EQ(back.height, 23);
    EXPECT_EQ(back.channels, channels);
    EXPECT_EQ(back.pixels, img.pixels);
  }
}

TEST(PngIo, MissingOrBrokenFileIsAnInputError) {
  testing::TempDir tmp;
  EXPECT_THROW(read_png(tmp.path() / "none.png"), InputError);
  testing::write_text(tmp.path() / "broken.png", "not a png");
  EXPECT_THROW(read_png(tmp.path() / "broken.png"), InputError);
}

namespace {
std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "no InputError";
}
}  // namespace

TEST(PngIo, InterlacedFilesReadAsTheSamePixels) {
  testing::TempDir tmp;
  for (int channels : {3, 4}) {
    Image img(29, 17, channels);
    for (size_t i = 0; i < img.pixels.size(); ++i) img.pixels[i] = uint8_t((i * 97 + 11) % 256);
    const auto path = tmp.path() / ("adam7_" + std::to_string(channels) + ".png");
    write_interlaced_png(path, img);
    const Image back = read_png(path);
    EXPECT_EQ(back.channels, channels);
    EXPECT_EQ(back.pixels, img.pixels);
  }
}

TEST(PngIo, HugeHeaderIsRefusedBeforeDecoding) {
  testing::TempDir tmp;
  const auto path = tmp.path() / "huge.png";
  write_header_only_png(path, 100000, 100000);
  const std::string expected = path.string() +
                               ": 100000x100000 pixels, larger than keyframe reads (at most 16384 a side and "
                               "67108864 pixels)";
  EXPECT_EQ(error_of([&] { read_png(path); }), expected);
  EXPECT_EQ(error_of([&] { read_png_header(path); }), expected);
  // Within the limits the header alone gives the size; the pixels (absent here) are not read.
  write_header_only_png(path, 8000, 10);
  const PngHeader h = read_png_header(path);
  EXPECT_EQ(h.width, 8000);
  EXPECT_EQ(h.height, 10);
  EXPECT_NE(error_of([&] { read_png(path); }).find("corrupt or truncated PNG"), std::string::npos);
}

}  // namespace kf::render
