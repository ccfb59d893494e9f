#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <memory>

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

// Mean absolute difference per channel (levels) between `tile` and the sheet's pixels at (x0, y0), over the
// tile less a one-pixel border; a large value when the tile does not fit there.
double tile_difference(const Image& sheet, const Image& tile, int x0, int y0) {
  if (x0 < 0 || y0 < 0 || x0 + tile.width > sheet.width || y0 + tile.height > sheet.height) return 1e9;
  double sum = 0;
  long n = 0;
  for (int y = 1; y + 1 < tile.height; ++y)
    for (int x = 1; x + 1 < tile.width; ++x)
      for (int c = 0; c < 3; ++c, ++n) sum += std::abs(int(sheet.at(x0 + x, y0 + y)[c]) - int(tile.at(x, y)[c]));
  return sum / double(n);
}

double image_difference(const Image& a, const Image& b) { return tile_difference(a, b, 0, 0); }

// The top row of the place in column `column` of the sheet (tiles sit kMargin + column (w + kGap) from the
// left, 16 + column (w + 10)) where `tile` appears, its frame's pixels to within a level; -1 when it is not there.
int row_of_tile(const Image& sheet, const Image& tile, int column) {
  const int x0 = 16 + column * (tile.width + 10);
  for (int y = 0; y + tile.height <= sheet.height; ++y)
    if (tile_difference(sheet, tile, x0, y) < 1.0) return y;
  return -1;
}

// Dark (type) pixels in the band under a tile where its caption is set.
int caption_ink(const Image& sheet, const Image& tile, int column, int tile_top) {
  const int x0 = 16 + column * (tile.width + 10), y0 = tile_top + tile.height + 2;
  int n = 0;
  for (int y = y0; y < std::min(y0 + 20, sheet.height); ++y)
    for (int x = x0; x < x0 + tile.width; ++x) n += sheet.at(x, y)[0] < 100;
  return n;
}

// A strip has one row per run, one tile per requested frame, and each tile is that run's frame as the
// renderer draws it, captioned; with `overlay` each run becomes one superimposed tile.
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

  const RunData flock = load_run(r.run_dirs[0]), cloth = load_run(r.run_dirs[1]);
  FrameRenderer flock_frames(flock, "osmesa", {80, 60, 0}), cloth_frames(cloth, "osmesa", {80, 60, 0});
  std::vector<Image> flock_tiles, cloth_tiles;
  for (int f : r.frames) flock_tiles.push_back(flock_frames.render(f)), cloth_tiles.push_back(cloth_frames.render(f));
  // The frames differ from each other, so finding each in its place below says which frame it is.
  EXPECT_GT(image_difference(flock_tiles[0], flock_tiles[2]), 1.0);
  EXPECT_GT(image_difference(cloth_tiles[0], cloth_tiles[2]), 1.0);
  EXPECT_GT(image_difference(flock_tiles[2], cloth_tiles[2]), 1.0);

  const int flock_row = row_of_tile(sheet, flock_tiles[0], 0), cloth_row = row_of_tile(sheet, cloth_tiles[0], 0);
  ASSERT_GT(flock_row, 0) << "the flock's frame 0 is not in the first column";
  ASSERT_GT(cloth_row, flock_row + 60) << "the cloth's frame 0 is not in a row under the flock's";
  for (int k = 0; k < 3; ++k) {
    EXPECT_LT(tile_difference(sheet, flock_tiles[size_t(k)], 16 + k * 90, flock_row), 1.0) << "flock, column " << k;
    EXPECT_LT(tile_difference(sheet, cloth_tiles[size_t(k)], 16 + k * 90, cloth_row), 1.0) << "cloth, column " << k;
    EXPECT_GT(caption_ink(sheet, flock_tiles[0], k, flock_row), 20) << "no caption under column " << k;
    EXPECT_GT(caption_ink(sheet, cloth_tiles[0], k, cloth_row), 20) << "no caption under column " << k;
  }
  EXPECT_GT(tile_difference(sheet, flock_tiles[2], 16, flock_row), 1.0);  // the frames are in request order
  EXPECT_EQ(row_of_tile(sheet, flock_tiles[0], 3), -1);                   // and there are three columns, not four

  r.overlay = true;
  r.name = "trail";
  const Image trail = read_png(make_figure(r));
  const Image flock_path = flock_frames.render_path(r.frames);
  const Image cloth_overlay = overlay_frames(cloth_tiles);
  EXPECT_GT(image_difference(cloth_overlay, cloth_tiles[2]), 0.1);  // the earlier frames show
  const int path_row = row_of_tile(trail, flock_path, 0), overlay_row = row_of_tile(trail, cloth_overlay, 0);
  EXPECT_GT(path_row, 0) << "the flock's path is not the first row's tile";
  EXPECT_GT(overlay_row, path_row + 60) << "the cloth's overlaid frames are not the second row's tile";
  EXPECT_EQ(row_of_tile(trail, cloth_tiles[2], 0), -1);  // not the plain last frame
  EXPECT_LT(trail.width, 16 + 2 * 90);                   // one tile a row

  r.frames = {9};
  r.name = "bad";
  EXPECT_THROW(make_figure(r), InputError);
  EXPECT_FALSE(std::filesystem::exists(tmp.path() / "figures/bad.png"));
  EXPECT_FALSE(std::filesystem::exists(tmp.path() / "figures/bad.pdf"));
}

// Mean absolute difference (levels) between the bands of `h` pixel rows just above y = a in one image and
// y = b in another, across the whole width.
double band_difference(const Image& one, int a, const Image& other, int b, int h) {
  if (a < h || b < h || a > one.height || b > other.height || one.width != other.width) return 1e9;
  double sum = 0;
  long n = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < one.width; ++x)
      for (int c = 0; c < 3; ++c, ++n) sum += std::abs(int(one.at(x, a - h + y)[c]) - int(other.at(x, b - h + y)[c]));
  return sum / double(n);
}

// Two runs of one scene: by default both rows are labelled with the scene's name; `labels` names each row.
TEST(Figure, LabelsNameEachRunsRow) {
  testing::TempDir tmp;
  FigureRequest r;
  r.run_dirs = {testing::make_flock_run(tmp.path() / "a"), testing::make_flock_run(tmp.path() / "b")};
  r.frames = {0};
  r.width = 80;
  r.height = 60;
  r.out_dir = tmp.path() / "figures";
  r.name = "plain";
  const Image plain = read_png(make_figure(r));
  r.name = "labelled";
  r.labels = {"Before", "After"};
  const Image labelled = read_png(make_figure(r));
  ASSERT_EQ(labelled.width, plain.width);
  ASSERT_EQ(labelled.height, plain.height);

  const RunData run = load_run(r.run_dirs[0]);
  FrameRenderer frames(run, "osmesa", {80, 60, 0});
  const Image tile = frames.render(0);
  const int first = row_of_tile(plain, tile, 0);
  ASSERT_GT(first, 20);
  int second = -1;
  for (int y = first + 60; second < 0 && y + 60 <= plain.height; ++y)
    if (tile_difference(plain, tile, 16, y) < 1.0) second = y;
  ASSERT_GT(second, first + 60);
  EXPECT_LT(tile_difference(labelled, tile, 16, first), 1.0);  // the tiles stay where they were
  EXPECT_LT(tile_difference(labelled, tile, 16, second), 1.0);
  // Each row's label line changed (both read "Flock" without labels), and only those lines: the title and the
  // captions are the same.
  EXPECT_EQ(band_difference(plain, first, plain, second, 16), 0.0);
  EXPECT_GT(band_difference(plain, first, labelled, first, 16), 0.5);
  EXPECT_GT(band_difference(plain, second, labelled, second, 16), 0.5);
  EXPECT_EQ(band_difference(plain, first - 30, labelled, first - 30, 10), 0.0);

  r.labels = {"Only one"};
  r.name = "bad";
  EXPECT_THROW(make_figure(r), InputError);
  EXPECT_FALSE(std::filesystem::exists(tmp.path() / "figures/bad.png"));
}

// Columns: one column per run in request order; with kLastKeyframe each run's tile is its own last keyframe
// (here frame 3 for a flock whose only keyframe is 3, the last frame for a cloth without keyframes); with
// several frames, time goes down.
TEST(Figure, ColumnsPutRunsSideBySideAtTheirLastKeyframe) {
  testing::TempDir tmp;
  FigureRequest r;
  const auto keyed = testing::make_flock_run(tmp.path() / "keyed");
  testing::write_text(keyed / "scene.json", R"({"time": {"frames": 5}, "flock": {"agents": 40},
    "objectives": [{"type": "shape", "frame": 3, "polygon": [[-5,-5],[5,-5],[5,5],[-5,5]]}]})");
  r.run_dirs = {keyed, testing::make_cloth_run(tmp.path() / "cloth", 8), testing::make_flock_run(tmp.path() / "flock2")};
  r.frames = {kLastKeyframe};
  r.columns = true;
  r.width = 80;
  r.height = 60;
  r.out_dir = tmp.path() / "figures";
  r.name = "fig1";
  const Image one_row = read_png(make_figure(r));

  std::vector<RunData> runs;
  for (const auto& d : r.run_dirs) runs.push_back(load_run(d));
  std::vector<std::unique_ptr<FrameRenderer>> renderers;
  for (const RunData& run : runs) renderers.push_back(std::make_unique<FrameRenderer>(run, "osmesa", RenderSettings{80, 60, 0}));
  const Image keyed3 = renderers[0]->render(3), keyed5 = renderers[0]->render(5);
  const Image cloth0 = renderers[1]->render(0), cloth5 = renderers[1]->render(5);
  const Image flock0 = renderers[2]->render(0), flock5 = renderers[2]->render(5);
  ASSERT_GT(image_difference(keyed3, keyed5), 1.0);  // frame 3 is told apart from the last frame

  const int row = row_of_tile(one_row, keyed3, 0);
  ASSERT_GT(row, 0) << "the first run's last keyframe (3) is not in the first column";
  EXPECT_GT(tile_difference(one_row, keyed5, 16, row), 1.0);  // its last frame is not what is shown
  EXPECT_LT(tile_difference(one_row, cloth5, 16 + 90, row), 1.0) << "the cloth's last frame, second column";
  EXPECT_LT(tile_difference(one_row, flock5, 16 + 2 * 90, row), 1.0) << "the second flock's last keyframe, third column";
  for (int k = 0; k < 3; ++k) EXPECT_GT(caption_ink(one_row, keyed3, k, row), 20) << "no run name under column " << k;
  EXPECT_LT(one_row.height, row + 60 + 60);  // one row of tiles

  r.frames = {0, kLastFrame};
  r.name = "fig6";
  const Image two_rows = read_png(make_figure(r));
  const int top = row_of_tile(two_rows, renderers[0]->render(0), 0);
  const int bottom = row_of_tile(two_rows, keyed5, 0);
  ASSERT_GT(top, 0);
  ASSERT_GT(bottom, top + 60) << "the last frame is not under frame 0";
  EXPECT_LT(tile_difference(two_rows, cloth0, 16 + 90, top), 1.0);
  EXPECT_LT(tile_difference(two_rows, cloth5, 16 + 90, bottom), 1.0);
  EXPECT_LT(tile_difference(two_rows, flock0, 16 + 2 * 90, top), 1.0);
  EXPECT_LT(tile_difference(two_rows, flock5, 16 + 2 * 90, bottom), 1.0);
  EXPECT_EQ(two_rows.width, one_row.width);
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
