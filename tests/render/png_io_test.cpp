#include <gtest/gtest.h>

#include "core/error.h"
#include "render/image/png_io.h"
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

}  // namespace kf::render
