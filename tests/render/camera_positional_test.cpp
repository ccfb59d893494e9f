// --camera takes up to three words, and the run directory (or scene) may come before or after them:
// "render --camera eye=… target=… RUN_DIR" renders the same frames as "render RUN_DIR --camera …".
#include <gtest/gtest.h>

#include "../reliability/cli_harness.h"
#include "core/error.h"
#include "render/image/image_diff.h"
#include "render/image/png_io.h"
#include "synthetic_runs.h"

namespace kf::render {
namespace {

namespace fs = std::filesystem;

class CameraPositional : public reliability::TempDirTest {
 protected:
  // Renders frame 0 of the synthetic flock with `args` and returns the image.
  Image render_with(const std::string& args) {
    fs::remove_all(dir_ / "flock/frames");
    const auto r = reliability::run_keyframe(args + " --size 64x48 --frames 0:1", dir_);
    EXPECT_EQ(r.code, kExitOk) << args << "\n" << r.output;
    return read_png(dir_ / "flock/frames/frame_0000.png");
  }
};

TEST_F(CameraPositional, RunDirBeforeOrAfterTheCameraWords) {
  testing::make_flock_run(dir_ / "flock");
  const Image after = render_with("render flock --camera eye=0,3,25 target=0,0,0");
  for (const char* args : {"render --camera eye=0,3,25 target=0,0,0 flock", "render --camera 'eye=0,3,25 target=0,0,0' flock",
                           "render --camera target=0,0,0 eye=0,3,25 flock"}) {
    SCOPED_TRACE(args);
    EXPECT_EQ(compare_images(after, render_with(args)).differing_fraction, 0.0);
  }
  // Three camera words and the run directory; the camera is not ignored: another field of view differs.
  const Image narrow = render_with("render --camera eye=0,3,25 target=0,0,0 fov=20 flock");
  EXPECT_EQ(compare_images(narrow, render_with("render flock --camera eye=0,3,25 target=0,0,0 fov=20")).differing_fraction, 0.0);
  EXPECT_GT(compare_images(after, narrow).differing_fraction, 0.05);
  EXPECT_GT(compare_images(after, render_with("render flock --view top")).differing_fraction, 0.05);
}

TEST_F(CameraPositional, MissingOrExtraRunDirsAreUsageErrors) {
  testing::make_flock_run(dir_ / "flock");
  auto r = reliability::run_keyframe("render --camera eye=0,3,25 target=0,0,0", dir_);
  EXPECT_EQ(r.code, kExitUsage) << r.output;
  EXPECT_NE(r.output.find("RUN_DIR is required"), std::string::npos) << r.output;
  r = reliability::run_keyframe("render flock --camera eye=0,3,25 target=0,0,0 flock", dir_);
  EXPECT_EQ(r.code, kExitUsage) << r.output;
  EXPECT_FALSE(fs::exists(dir_ / "flock/frames"));
  r = reliability::run_keyframe("render flock --camera eye=0,3,25 target=0,0,0 fov=20 fov=30", dir_);
  EXPECT_EQ(r.code, kExitInput) << r.output;
  EXPECT_NE(r.output.find("--camera: expected at most 3 words"), std::string::npos) << r.output;
  r = reliability::run_keyframe("figure --camera eye=0,3,25 target=0,0,0 --out-dir figs", dir_);
  EXPECT_EQ(r.code, kExitUsage) << r.output;
  EXPECT_NE(r.output.find("RUN_DIR is required"), std::string::npos) << r.output;
}

TEST_F(CameraPositional, FigureAndRunTakeTheirPositionalsAfterTheCamera) {
  testing::make_flock_run(dir_ / "flock");
  testing::make_flock_run(dir_ / "flock2");
  // Two run directories after the camera: two rows, as when they come first.
  auto r = reliability::run_keyframe(
      "figure --camera eye=0,3,25 target=0,0,0 flock flock2 --size 64x48 --frames 0 --name after --out-dir figs", dir_);
  ASSERT_EQ(r.code, kExitOk) << r.output;
  r = reliability::run_keyframe(
      "figure flock flock2 --camera eye=0,3,25 target=0,0,0 --size 64x48 --frames 0 --name before --out-dir figs", dir_);
  ASSERT_EQ(r.code, kExitOk) << r.output;
  const Image after = read_png(dir_ / "figs/after.png"), before = read_png(dir_ / "figs/before.png");
  EXPECT_EQ(compare_images(after, before).differing_fraction, 0.0);
  EXPECT_GT(after.height, 2 * 48);  // two rows

  write("small.json", reliability::small_flock_scene());
  // The scene is read after the camera (its 8 evaluations need not reach the keyframe: exit 0 or 7).
  r = reliability::run_keyframe("run --camera eye=0,3,25 target=0,0,0 small.json --size 64x48 --quiet", dir_);
  ASSERT_NE(r.code, kExitUsage) << r.output;
  EXPECT_NE(r.output.find("rendered 21 frames into out/small/frames"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(dir_ / "out/small/frames/frame_0000.png"));
}

}  // namespace
}  // namespace kf::render
