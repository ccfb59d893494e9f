// keyframe compare from the command line: exit 0 when frames match, 1 when one differs (with its report),
// 3 with one line on bad input, --noise and --update as options.
#include <gtest/gtest.h>

#include "../reliability/cli_harness.h"
#include "core/error.h"
#include "render/image/png_io.h"
#include "../render/png_files.h"

namespace kf {
namespace {

namespace fs = std::filesystem;
using reliability::read_text;
using reliability::run_keyframe;

// Three 40x30 frames: a grey ground with a dark square that moves one column per frame.
void write_frames(const fs::path& dir, int shift = 0, int noise = 0) {
  fs::create_directories(dir);
  for (int f = 0; f < 3; ++f) {
    render::Image img(40, 30, 3);
    for (int y = 0; y < 30; ++y)
      for (int x = 0; x < 40; ++x) {
        const bool square = x >= 5 + f + shift && x < 15 + f + shift && y >= 10 && y < 20;
        // A sparse +-noise pattern, like a few noisy samples.
        const int n = ((x * 7 + y * 13 + f) % 41 == 0) ? noise : 0;
        for (int c = 0; c < 3; ++c) img.at(x, y)[c] = uint8_t((square ? 30 : 200) + n);
      }
    char name[32];
    std::snprintf(name, sizeof name, "frame_%04d.png", f);
    render::write_png(dir / name, img);
  }
}

class CompareCli : public reliability::TempDirTest {};

TEST_F(CompareCli, ExitCodesForPassFailAndNoise) {
  write_frames(dir_ / "ref");
  write_frames(dir_ / "run/frames");
  auto r = run_keyframe("compare run ref", dir_);
  EXPECT_EQ(r.code, kExitOk) << r.output;
  EXPECT_NE(r.output.find("3 frames, 3 pass, 0 fail"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(dir_ / "run/compare/compare.json"));
  EXPECT_TRUE(fs::exists(dir_ / "run/compare/junit.xml"));

  write_frames(dir_ / "noisy", 0, 30);
  r = run_keyframe("compare noisy ref --out noisy-report", dir_);
  EXPECT_EQ(r.code, kExitDifferent) << r.output;
  r = run_keyframe("compare noisy ref --out noisy-report --noise", dir_);
  EXPECT_EQ(r.code, kExitOk) << r.output;
  r = run_keyframe("compare noisy ref --out noisy-report --noise --tolerance 10", dir_);  // options override --noise
  EXPECT_EQ(r.code, kExitDifferent) << r.output;

  write_frames(dir_ / "moved", 3);
  r = run_keyframe("compare moved ref --out moved-report --noise", dir_);
  EXPECT_EQ(r.code, kExitDifferent) << r.output;
  EXPECT_NE(r.output.find("FAIL frame_0001.png"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("3 of 3 frames differ"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(dir_ / "moved-report/frame_0001_diff.png"));
  EXPECT_TRUE(fs::exists(dir_ / "moved-report/frame_0001_side.png"));
  EXPECT_NE(read_text(dir_ / "moved-report/junit.xml").find("failures=\"3\""), std::string::npos);

  const std::string before = read_text(dir_ / "ref/frame_0001.png");
  EXPECT_EQ(run_keyframe("compare moved ref", dir_).code, kExitDifferent);
  EXPECT_EQ(read_text(dir_ / "ref/frame_0001.png"), before);
  r = run_keyframe("compare moved ref --update", dir_);
  EXPECT_EQ(r.code, kExitOk) << r.output;
  EXPECT_EQ(read_text(dir_ / "ref/frame_0001.png"), read_text(dir_ / "moved/frame_0001.png"));
  EXPECT_EQ(run_keyframe("compare moved ref", dir_).code, kExitOk);
}

// Each bad input: exit 3 and a single line that names the problem.
TEST_F(CompareCli, BadInputExitsThreeWithOneLine) {
  write_frames(dir_ / "ref");
  write_frames(dir_ / "a");
  fs::create_directories(dir_ / "empty");
  fs::remove(dir_ / "a/frame_0002.png");
  write_frames(dir_ / "extra");
  fs::copy_file(dir_ / "ref/frame_0000.png", dir_ / "extra/frame_0009.png");
  write_frames(dir_ / "sized");
  render::write_png(dir_ / "sized/frame_0001.png", render::Image(41, 30, 3));
  write_frames(dir_ / "cut");
  const std::string png = read_text(dir_ / "cut/frame_0000.png");
  reliability::write_text(dir_ / "cut/frame_0000.png", png.substr(0, png.size() - 30));
  // A header claiming 100000 x 100000 pixels (it once ended in std::bad_alloc, exit 10).
  write_frames(dir_ / "huge");
  render::write_header_only_png(dir_ / "huge/frame_0001.png", 100000, 100000);
  const std::pair<const char*, const char*> cases[] = {
      {"compare huge ref", "frame_0001.png: 100000x100000 pixels, larger than keyframe reads"},
      {"compare a ref", "frame_0002.png: missing"},
      {"compare extra ref", "missing reference for"},
      {"compare sized ref", "41x30 pixels, but the reference"},
      {"compare cut ref", "corrupt or truncated PNG"},
      {"compare empty ref", "no PNG frames to compare"},
      {"compare ref empty", "no PNG reference frames"},
      {"compare ref ref --out ref", "reports cannot go into a frames directory"},
  };
  for (const auto& [args, message] : cases) {
    const auto r = run_keyframe(args, dir_);
    EXPECT_EQ(r.code, kExitInput) << args << "\n" << r.output;
    EXPECT_NE(r.output.find(message), std::string::npos) << args << "\n" << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << args << "\n" << r.output;
  }
}

}  // namespace
}  // namespace kf
