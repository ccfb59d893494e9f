// --view-frames A:B: the automatic camera frames what frames A..B-1 show instead of the whole run, so a
// sheet that travels metres is drawn large in the frames asked for; bad ranges are one-line errors.
#include <gtest/gtest.h>

#include <algorithm>

#include "../reliability/cli_harness.h"
#include "core/error.h"
#include "render/camera_choice.h"
#include "render/frame_range_bounds.h"
#include "render/frame_renderer.h"
#include "synthetic_runs.h"

namespace kf::render {
namespace {

namespace fs = std::filesystem;
constexpr int kW = 160, kH = 120;

// The synthetic 1.5 m sheet carried 6 m along +x over its 6 frames (1.2 m a frame), plain blue on white.
RunData travelling_sheet(const fs::path& dir) {
  RunData run = load_run(testing::make_cloth_run(dir, 8));
  for (int f = 0; f < run.trajectory.frames(); ++f)
    for (int i = 0; i < run.trajectory.particles; ++i) run.trajectory.x[size_t(f)][3 * i] += 1.2 * f;
  RenderSpec& rs = run.scene.render;
  rs.ground = false;
  rs.checker = 0;
  rs.cloth_front = rs.cloth_back = Vec3(0.2, 0.3, 0.8);
  rs.background = Vec3(1, 1, 1);
  return run;
}

int blue_pixels(const Image& img) {
  int n = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const uint8_t* p = img.at(x, y);
      n += p[2] > 90 && p[2] > p[0] + 40;
    }
  return n;
}

CameraChoice frames(int begin, int end) {
  CameraChoice c;
  c.frames = std::make_pair(begin, end);
  return c;
}

TEST(ViewFrames, TheCameraFramesTheChosenFramesAndDrawsTheSheetLarger) {
  testing::TempDir tmp;
  RunData run = travelling_sheet(tmp.path() / "cloth");
  FrameRenderer whole(run, "osmesa", {kW, kH, 4});
  FrameRenderer first(run, "osmesa", {kW, kH, 4}, frames(0, 1));
  // It looks at the middle of frame 0's sheet, the whole-run camera at the middle of the whole path.
  const Bounds b0 = frame_range_bounds(run.scene, run.trajectory, nullptr, 0, 1);
  EXPECT_LT((first.camera().target - b0.center()).norm(), 1e-9);
  EXPECT_NEAR(whole.camera().target.x(), 3.0, 1e-6);
  const int small = blue_pixels(whole.render(0)), large = blue_pixels(first.render(0));
  std::printf("frame 0's sheet: %d pixels framed with the whole run, %d framed alone\n", small, large);
  ASSERT_GT(small, 0);
  EXPECT_GT(large, 4 * small);
  // The scene's own camera does not override a range: it is framed automatically.
  run.scene.render.has_camera = true;
  run.scene.render.camera.eye = Vec3(0, 50, 50);
  FrameRenderer scene_camera(run, "osmesa", {kW, kH, 4}, frames(0, 1));
  EXPECT_LT((scene_camera.camera().target - b0.center()).norm(), 1e-9);
  // "A:" runs to the end: frames 4 and 5 are centred on x = 5.4 m.
  FrameRenderer last(run, "osmesa", {kW, kH, 4}, frames(4, -1));
  EXPECT_NEAR(last.camera().target.x(), 5.4, 1e-6);
}

TEST(ViewFrames, ARangeOutsideTheRunIsRefusedNamingIt) {
  testing::TempDir tmp;
  const RunData run = travelling_sheet(tmp.path() / "cloth");
  for (const auto& [b, e] : {std::pair{3, 9}, std::pair{6, -1}, std::pair{2, 2}}) {
    try {
      FrameRenderer r(run, "osmesa", {kW, kH, 4}, frames(b, e));
      ADD_FAILURE() << b << ":" << e << " accepted";
    } catch (const InputError& err) {
      EXPECT_EQ(std::string(err.what()).rfind("--view-frames: expected frames within 0:6 (the run's frames 0..5), got ", 0), 0u)
          << err.what();
    }
  }
}

class ViewFramesCli : public reliability::TempDirTest {};

TEST_F(ViewFramesCli, RenderTakesARangeAndRefusesBadOnesWithoutWritingFrames) {
  testing::make_cloth_run(dir_ / "cloth");
  auto r = reliability::run_keyframe("render cloth --size 64x48 --frames 2:3 --view-frames 2:", dir_);
  ASSERT_EQ(r.code, kExitOk) << r.output;
  EXPECT_TRUE(fs::exists(dir_ / "cloth/frames/frame_0002.png"));
  r = reliability::run_keyframe("render cloth --size 64x48 --frames 0:1 --view side --view-frames 0:1", dir_);
  ASSERT_EQ(r.code, kExitOk) << r.output;
  fs::remove_all(dir_ / "cloth/frames");
  for (const char* bad : {"render cloth --view-frames 4:99", "render cloth --view-frames x",
                          "render cloth --view-frames 0:2 --camera 'eye=0,1,5 target=0,1,0'"}) {
    SCOPED_TRACE(bad);
    r = reliability::run_keyframe(bad, dir_);
    EXPECT_EQ(r.code, kExitInput) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_NE(r.output.find("--view-frames"), std::string::npos) << r.output;
  }
  EXPECT_FALSE(fs::exists(dir_ / "cloth/frames"));
}

}  // namespace
}  // namespace kf::render
