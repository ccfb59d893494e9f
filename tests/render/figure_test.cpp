#include <gtest/gtest.h>

#include <algorithm>

#include "core/error.h"
#include "render/figure/figure_sheet.h"
#include "render/figure/make_figure.h"
#include "render/frame_renderer.h"
#include "render/image/png_io.h"
#include "synthetic_runs.h"

namespace kf::render {

// Rows where some pixel is darker than `level` (type or tiles), from `y0` to `y1` (exclusive).
int inked_rows(const Image& img, int y0, int y1, int level = 128) {
  int rows = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = 0; x < img.width; ++x)
      if (img.at(x, y)[0] < level) {
        ++rows;
        break;
      }
  return rows;
}

TEST(FigureSheet, TypesetsTitleLabelsAndAWrappedCaption) {
  FigureSheet s;
  s.title = "Square then cross";
  Image tile(120, 80, 3);
  std::fill(tile.pixels.begin(), tile.pixels.end(), uint8_t(230));  // light, so only type is dark
  s.rows.push_back({"Flock", {tile, tile}, {"Frame 0", "Frame 45 (keyframe)"}});
  const Image bare = compose_sheet(s);
  EXPECT_EQ(bare.width, 2 * 16 + 2 * 120 + 10);
  EXPECT_GT(inked_rows(bare, 0, 40), 8);  // the title's type
  s.caption = "Fig. 1 left: 200 agents form a square (frame 45) then a cross (frame 90); a caption this long "
              "wraps onto more than one line under the figure.";
  const Image captioned = compose_sheet(s);
  EXPECT_EQ(captioned.width, bare.width);  // the caption wraps instead of widening the sheet
  EXPECT_GT(captioned.height, bare.height + 2 * 15);  // at least two lines
  EXPECT_GT(inked_rows(captioned, bare.height - 16, captioned.height), 15);
  EXPECT_EQ(inked_rows(bare, bare.height - 12, bare.height), 0);  // a white margin at the bottom

  const std::string pdf = sheet_pdf(s);
  ASSERT_GT(pdf.size(), 1000u);
  EXPECT_EQ(pdf.substr(0, 5), "%PDF-");
  EXPECT_NE(pdf.find("DejaVu"), std::string::npos);  // type embedded as a font, not pixels
  s.rows[0].tiles.push_back(Image(60, 80, 3));
  EXPECT_THROW(compose_sheet(s), std::invalid_argument);
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
  EXPECT_GT(std::filesystem::file_size(tmp.path() / "figures/sheet.pdf"), 1000u);  // beside the PNG
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
  EXPECT_FALSE(std::filesystem::exists(tmp.path() / "figures/bad.pdf"));
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

// The path view of a flock (fig. 3): the last frame plus earlier snapshots, red trails and the centre of
// mass. Against the plain last frame it adds reddish trail pixels and more agent pixels.
TEST(Figure, FlockPathAddsTrailsSnapshotsAndTheCentreOfMass) {
  testing::TempDir tmp;
  const RunData run = load_run(testing::make_flock_run(tmp.path() / "flock"));
  FrameRenderer renderer(run, "osmesa", {160, 120, 0});
  const Image plain = renderer.render(5), path = renderer.render_path({0, 3, 5});
  auto count = [](const Image& img, auto pred) {
    int n = 0;
    for (size_t i = 0; i + 2 < img.pixels.size(); i += 3) n += pred(img.pixels[i], img.pixels[i + 1], img.pixels[i + 2]);
    return n;
  };
  auto reddish = [](int r, int g, int b) { return r > g + 40 && r > b + 40; };
  auto dark = [](int r, int g, int b) { return r + g + b < 3 * 110; };
  EXPECT_GT(count(path, reddish), count(plain, reddish) + 20);  // the trails (the plain frame's orange path counts too)
  EXPECT_GT(count(path, dark), count(plain, dark));
  const RunData cloth = load_run(testing::make_cloth_run(tmp.path() / "cloth", 8));
  FrameRenderer cloth_renderer(cloth, "osmesa", {160, 120, 0});
  EXPECT_THROW(cloth_renderer.render_path({0, 5}), InputError);
}

}  // namespace kf::render
