// A shape keyframe read from an SVG file, through the command line: simulated into a run directory (whose
// scene copy names the SVG file absolutely), rendered from above, and drawn the way round the SVG shows it.
#include <gtest/gtest.h>

#include "../reliability/cli_harness.h"
#include "core/error.h"
#include "render/image/png_io.h"

namespace kf::render {
namespace {

namespace fs = std::filesystem;

class SvgShapeRender : public reliability::TempDirTest {};

TEST_F(SvgShapeRender, TheTopViewShowsTheSvgDrawingUnmirrored) {
  // An "L" in SVG's frame (y down): a bar on the left, its foot at the bottom, reaching right.
  fs::create_directories(dir_ / "art");
  write("art/l.svg", R"(<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 3 4">
  <path d="M 0 0 H 1 V 3 H 3 V 4 H 0 Z"/>
</svg>
)");
  // Ground: x in [-3, 3], z in [-4, 4]; the foot is z in [2, 4].
  write("l.json", R"({"seed": 3, "time": {"fps": 30, "frames": 6},
  "flock": {"agents": 6, "spawn": {"radius": 2}},
  "objectives": [{"type": "shape", "frame": 6, "svg_path": {"file": "art/l.svg", "scale": 2, "offset": [-3, -4]}}],
  "render": {"width": 160, "height": 160, "checker": 0, "background": [1, 1, 1], "ground_color": [1, 1, 1],
             "agent_color": [0.1, 0.1, 0.1], "target_color": [0.05, 0.9, 0.05]}})");
  auto r = reliability::run_keyframe("simulate l.json --out runs/l", dir_);
  ASSERT_EQ(r.code, kExitOk) << r.output;
  // The run's scene copy reads from anywhere: rendered from another directory.
  fs::create_directories(dir_ / "elsewhere");
  r = reliability::run_keyframe("render ../runs/l --size 160x160 --frames 0:1 --view top", dir_ / "elsewhere");
  ASSERT_EQ(r.code, kExitOk) << r.output;
  const Image img = read_png(dir_ / "runs/l/frames/frame_0000.png");
  auto green = [&](int x, int y) {
    const uint8_t* p = img.at(x, y);
    return p[1] > 90 && p[1] > 2 * p[0] && p[1] > 2 * p[2];
  };
  int lo_x = img.width, hi_x = -1, lo_y = img.height, hi_y = -1;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      if (green(x, y)) lo_x = std::min(lo_x, x), hi_x = std::max(hi_x, x), lo_y = std::min(lo_y, y), hi_y = std::max(hi_y, y);
  ASSERT_GT(hi_x - lo_x, 20) << "the outline is not drawn";
  ASSERT_GT(hi_y - lo_y, 20);
  // Its box is 3 wide by 4 tall, as drawn.
  EXPECT_NEAR(double(hi_y - lo_y) / (hi_x - lo_x), 4.0 / 3.0, 0.15);
  // The right half of the box holds only the foot: the bottom quarter, and it has pixels there.
  int right = 0;
  for (int y = lo_y; y <= hi_y; ++y)
    for (int x = (lo_x + hi_x) / 2 + 2; x <= hi_x; ++x)
      if (green(x, y)) {
        ++right;
        EXPECT_GT(y, lo_y + 0.7 * (hi_y - lo_y)) << "pixel " << x << ", " << y;
      }
  EXPECT_GT(right, 20);
  // The left edge runs the full height: the bar is on the left.
  int left_rows = 0;
  for (int y = lo_y; y <= hi_y; ++y)
    for (int x = lo_x; x < lo_x + 4; ++x)
      if (green(x, y)) {
        ++left_rows;
        break;
      }
  EXPECT_GT(left_rows, 0.8 * (hi_y - lo_y));
}

}  // namespace
}  // namespace kf::render
