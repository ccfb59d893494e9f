#include <gtest/gtest.h>

#include "core/error.h"
#include "render/figure/bitmap_font.h"
#include "render/figure/make_figure.h"
#include "render/image/png_io.h"
#include "synthetic_runs.h"

namespace kf::render {

TEST(BitmapFont, DrawsInkInsideItsBox) {
  Image img(60, 20, 3);
  const uint8_t ink[3] = {255, 255, 255};
  draw_text(img, 2, 3, "K1", 2, ink);
  int lit = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      if (img.at(x, y)[0]) {
        ++lit;
        EXPECT_GE(x, 2);
        EXPECT_LT(x, 2 + text_width("K1", 2));
        EXPECT_GE(y, 3);
        EXPECT_LT(y, 3 + text_height(2));
      }
  EXPECT_GT(lit, 40);
}

TEST(Figure, StripOfTwoRunsAndOverlay) {
  testing::TempDir tmp;
  FigureRequest r;
  r.run_dirs = {testing::make_flock_run(tmp.path() / "flock"), testing::make_cloth_run(tmp.path() / "cloth", 8)};
  r.frames = {0, 3, 5};
  r.width = 80;
  r.height = 60;
  r.out_dir = tmp.path() / "figures";
  r.name = "sheet";
  const auto path = make_figure(r);
  EXPECT_EQ(path, tmp.path() / "figures/sheet.png");
  const Image sheet = read_png(path);
  EXPECT_GT(sheet.width, 3 * 80);
  EXPECT_GT(sheet.height, 2 * 60);
  r.overlay = true;
  r.name = "trail";
  const Image trail = read_png(make_figure(r));
  EXPECT_LT(trail.width, sheet.width);

  r.frames = {9};
  r.name = "bad";
  EXPECT_THROW(make_figure(r), InputError);
  EXPECT_FALSE(std::filesystem::exists(tmp.path() / "figures/bad.png"));
}

TEST(Figure, ColumnsPutRunsSideBySideAtTheirLastKeyframe) {
  testing::TempDir tmp;
  FigureRequest r;
  r.run_dirs = {testing::make_flock_run(tmp.path() / "flock"), testing::make_cloth_run(tmp.path() / "cloth", 8),
                testing::make_flock_run(tmp.path() / "flock2")};
  r.frames = {kLastKeyframe};
  r.columns = true;
  r.width = 80;
  r.height = 60;
  r.out_dir = tmp.path() / "figures";
  r.name = "fig1";
  const Image one_row = read_png(make_figure(r));
  EXPECT_GT(one_row.width, 3 * 80);  // three runs across
  EXPECT_LT(one_row.height, 2 * 60 + 100);
  r.frames = {0, kLastFrame};
  r.name = "fig6";
  const Image two_rows = read_png(make_figure(r));
  EXPECT_EQ(two_rows.width, one_row.width);
  EXPECT_GT(two_rows.height, one_row.height + 60);
}

}  // namespace kf::render
