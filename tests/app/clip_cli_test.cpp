// keyframe clip from the command line, as the README shows it: render, then encode frames and a turntable.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>

#include "../reliability/cli_harness.h"
#include "../render/synthetic_runs.h"
#include "core/error.h"
#include "render/clip/make_clip.h"

namespace kf {
namespace {

namespace fs = std::filesystem;
using reliability::run_keyframe;

class ClipCli : public reliability::TempDirTest {};

TEST_F(ClipCli, RenderThenClipMp4GifAndTurntable) {
  if (render::find_program("ffmpeg").empty()) {
    // scripts/setup installs ffmpeg, so CI (CI=true) must encode.
    if (std::getenv("CI")) FAIL() << "ffmpeg not installed; scripts/setup installs it";
    GTEST_SKIP() << "ffmpeg not installed";
  }
  render::testing::make_flock_run(dir_ / "flock");
  auto r = run_keyframe("render flock --size 64x48", dir_);
  ASSERT_EQ(r.code, kExitOk) << r.output;
  r = run_keyframe("clip flock --gif", dir_);
  ASSERT_EQ(r.code, kExitOk) << r.output;
  EXPECT_NE(r.output.find("clip -> flock/clip.mp4"), std::string::npos) << r.output;
  EXPECT_GT(fs::file_size(dir_ / "flock/clip.mp4"), 100u);
  EXPECT_GT(fs::file_size(dir_ / "flock/clip.gif"), 100u);
  r = run_keyframe("render flock --size 64x48 --turntable 10", dir_);
  ASSERT_EQ(r.code, kExitOk) << r.output;
  r = run_keyframe("clip flock --turntable --gif-only", dir_);
  ASSERT_EQ(r.code, kExitOk) << r.output;
  EXPECT_GT(fs::file_size(dir_ / "flock/turntable.gif"), 100u);
  EXPECT_FALSE(fs::exists(dir_ / "flock/turntable.mp4"));  // --gif-only
  r = run_keyframe("clip flock --ffmpeg /nonexistent/ffmpeg", dir_);
  EXPECT_EQ(r.code, kExitNotReady) << r.output;
}

// ffmpeg skips a frame it cannot decode and exits 0, so a truncated frame is refused before encoding:
// exit 3, one line naming the frame, no clip (whether or not ffmpeg is installed).
TEST_F(ClipCli, TruncatedFrameIsExitThreeAndNoClip) {
  render::testing::make_flock_run(dir_ / "flock");
  ASSERT_EQ(run_keyframe("render flock --size 64x48", dir_).code, kExitOk);
  const fs::path frame = dir_ / "flock/frames/frame_0003.png";
  fs::resize_file(frame, fs::file_size(frame) / 2);
  const auto before = reliability::list_tree(dir_);
  for (const char* args : {"clip flock --gif", "clip flock --ffmpeg /bin/true"}) {
    const auto r = run_keyframe(args, dir_);
    EXPECT_EQ(r.code, kExitInput) << args << "\n" << r.output;
    EXPECT_EQ(r.output.rfind("keyframe: error: flock/frames/frame_0003.png: corrupt or truncated PNG", 0), 0u) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_EQ(reliability::list_tree(dir_), before) << args;
  }
}

}  // namespace
}  // namespace kf
