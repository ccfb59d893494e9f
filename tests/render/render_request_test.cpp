// A bad render request fails with its own one-line message and writes nothing.
#include <gtest/gtest.h>

#include "core/error.h"
#include "render/image/png_io.h"
#include "render/render_run.h"
#include "synthetic_runs.h"

namespace kf::render {

namespace {
std::string error_of(const RenderRequest& r) {
  try {
    render_run(r);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}
}  // namespace

TEST(RenderRequest, EachBadRequestHasItsOwnErrorAndWritesNothing) {
  testing::TempDir tmp;
  const auto run = testing::make_flock_run(tmp.path() / "flock");
  struct Case {
    RenderRequest r;
    std::string expected;
  };
  std::vector<Case> cases;
  RenderRequest base;
  base.run_dir = run;
  base.width = 64;
  base.height = 48;
  {
    Case c{base, "unknown render back end \"vulkan\" (expected one of: osmesa, embree)"};
    c.r.backend = "vulkan";
    cases.push_back(c);
  }
  {
    Case c{base, "image size 0x48 out of range"};
    c.r.width = 0;
    cases.push_back(c);
  }
  {
    Case c{base, "image size 64x100000 out of range"};
    c.r.height = 100000;
    cases.push_back(c);
  }
  {
    Case c{base, "frames 4:99 out of range"};
    c.r.frame_begin = 4;
    c.r.frame_end = 99;
    cases.push_back(c);
  }
  {
    Case c{base, "frames 6:-1 out of range"};
    c.r.frame_begin = 6;
    cases.push_back(c);
  }
  for (const auto& c : cases) {
    const std::string e = error_of(c.r);
    EXPECT_EQ(e.rfind(c.expected, 0), 0u) << "got: " << e;
    EXPECT_EQ(e.find('\n'), std::string::npos);
    EXPECT_FALSE(std::filesystem::exists(run / "frames")) << c.expected;
  }
  std::filesystem::remove(run / "trajectory.bin");
  const std::string e = error_of(base);
  EXPECT_NE(e.find("no trajectory.bin"), std::string::npos) << e;
  EXPECT_FALSE(std::filesystem::exists(run / "frames"));
  base.run_dir = tmp.path() / "missing";
  EXPECT_NE(error_of(base).find("not a run directory"), std::string::npos);
}

TEST(RenderRequest, WritesTheRequestedFramesOnly) {
  testing::TempDir tmp;
  RenderRequest r;
  r.run_dir = testing::make_cloth_run(tmp.path() / "cloth", 8);
  r.width = 48;
  r.height = 32;
  r.frame_begin = 2;
  r.frame_end = 4;
  EXPECT_EQ(render_run(r), 2);
  EXPECT_FALSE(std::filesystem::exists(r.run_dir / "frames/frame_0001.png"));
  EXPECT_TRUE(std::filesystem::exists(r.run_dir / "frames/frame_0002.png"));
  EXPECT_TRUE(std::filesystem::exists(r.run_dir / "frames/frame_0003.png"));
  EXPECT_FALSE(std::filesystem::exists(r.run_dir / "frames/frame_0004.png"));
  const Image img = read_png(r.run_dir / "frames/frame_0002.png");
  EXPECT_EQ(img.width, 48);
  EXPECT_EQ(img.height, 32);
}

}  // namespace kf::render
