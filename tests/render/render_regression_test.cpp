// Visual regression: small frames of synthetic runs against references in tests/render/reference/.
//
// Regenerate the references deliberately with
//   KEYFRAME_UPDATE_REFERENCES=1 ./build/release/keyframe_tests --gtest_filter='RenderRegression.*'
// then look at the PNGs and commit them. A failing comparison writes <name>_actual.png and
// <name>_diff.png into its temporary directory (printed in the failure message).
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <array>
#include <cstdlib>
#include <functional>
#include <set>

#include "render/frame_renderer.h"
#include "render/image/image_diff.h"
#include "synthetic_runs.h"

namespace kf::render {

namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 160, kHeight = 120;
// Tolerance: llvmpipe and Embree are deterministic here; this leaves room for other CPUs' rounding.
constexpr double kMaxMeanError = 0.5;         // 8-bit levels
constexpr double kMaxDifferingFraction = 0.002;  // of pixels off by more than 8 levels

struct Case {
  const char* name;
  bool flock;
  const char* backend;
  int spp;
  int frame;
};

const Case kCases[] = {
    {"flock_osmesa", true, "osmesa", 4, 3},
    {"cloth_osmesa", false, "osmesa", 4, 2},
    {"flock_embree", true, "embree", 4, 3},
    {"cloth_embree", false, "embree", 4, 2},
};

Image render_case(const Case& c, const fs::path& tmp, const std::function<void(RunData&)>& tweak = {}) {
  const fs::path dir = c.flock ? testing::make_flock_run(tmp / c.name) : testing::make_cloth_run(tmp / c.name, 16);
  RunData run = load_run(dir);
  if (run.scene.cloth) {
    // Colliders are added here so the test does not depend on how the scene file spells them.
    SphereShape sphere;
    sphere.center = Vec3(0.2, 0.45, 0.1);
    sphere.radius = 0.3;
    TorusShape ring;
    ring.center = Vec3(-0.4, 1.5, -0.3);
    ring.axis = Vec3(0, 0.3, 1).normalized();
    ring.radius = 0.25;
    ring.tube_radius = 0.03;
    run.scene.cloth->colliders = {{sphere}, {ring}, {GroundShape{}}};
  }
  if (tweak) tweak(run);
  FrameRenderer renderer(run, c.backend, {kWidth, kHeight, c.spp});
  return renderer.render(c.frame);
}

fs::path reference_path(const Case& c) {
  return fs::path(KEYFRAME_SOURCE_DIR) / "tests/render/reference" / (std::string(c.name) + ".png");
}

bool updating() {
  const char* v = std::getenv("KEYFRAME_UPDATE_REFERENCES");
  return v && std::string(v) == "1";
}

::testing::AssertionResult matches(const Image& actual, const Image& reference, const fs::path& tmp,
                                   const std::string& name) {
  if (actual.width != reference.width || actual.height != reference.height)
    return ::testing::AssertionFailure() << name << ": size differs from the reference";
  const ImageDifference d = compare_images(actual, reference);
  if (d.mean_error <= kMaxMeanError && d.differing_fraction <= kMaxDifferingFraction)
    return ::testing::AssertionSuccess() << name << ": mean error " << d.mean_error << ", differing "
                                         << d.differing_fraction;
  write_png(tmp / (name + "_actual.png"), actual);
  write_png(tmp / (name + "_diff.png"), difference_image(actual, reference));
  return ::testing::AssertionFailure() << name << ": mean error " << d.mean_error << " (max " << kMaxMeanError
                                       << "), differing pixels " << d.differing_fraction << " (max "
                                       << kMaxDifferingFraction << "), worst " << d.max_error
                                       << " levels; see " << (tmp / (name + "_diff.png")).string();
}

class RenderRegression : public ::testing::TestWithParam<Case> {};

}  // namespace

TEST_P(RenderRegression, MatchesReference) {
  testing::TempDir tmp;
  const Case& c = GetParam();
  const Image img = render_case(c, tmp.path());
  if (updating()) {
    write_png(reference_path(c), img);
    GTEST_SKIP() << "wrote " << reference_path(c).string();
  }
  ASSERT_TRUE(fs::exists(reference_path(c)))
      << reference_path(c).string() << " missing; run with KEYFRAME_UPDATE_REFERENCES=1 to create it";
  const Image ref = read_png(reference_path(c));
  EXPECT_TRUE(matches(img, ref, tmp.path(), c.name));
  // The picture is not blank or flat: shading gives many distinct colours (sky, ground, objects, shadows).
  std::set<std::array<uint8_t, 3>> colours;
  for (size_t i = 0; i + 2 < img.pixels.size(); i += 3)
    colours.insert({img.pixels[i], img.pixels[i + 1], img.pixels[i + 2]});
  EXPECT_GE(colours.size(), 64u);
}

TEST_P(RenderRegression, RepeatedRendersAgree) {
  testing::TempDir tmp;
  const Image a = render_case(GetParam(), tmp.path() / "a"), b = render_case(GetParam(), tmp.path() / "b");
  EXPECT_TRUE(matches(a, b, tmp.path(), "repeat"));
  EXPECT_EQ(a.pixels, b.pixels);
}

TEST_P(RenderRegression, SlightlyDifferentColourOrCameraIsCaught) {
  if (updating()) GTEST_SKIP();
  testing::TempDir tmp;
  const Case& c = GetParam();
  const Image ref = read_png(reference_path(c));
  const Image colour = render_case(c, tmp.path() / "colour", [](RunData& run) {
    auto& rs = run.scene.render;
    if (run.scene.flock)
      rs.agent_color += Vec3(0.08, 0.0, 0.0);
    else
      rs.cloth_back += Vec3(0.0, -0.05, 0.0);
  });
  EXPECT_FALSE(matches(colour, ref, tmp.path(), "colour"));
  const Image camera = render_case(c, tmp.path() / "camera", [](RunData& run) { run.scene.render.fov += 1.0; });
  EXPECT_FALSE(matches(camera, ref, tmp.path(), "camera"));
}

INSTANTIATE_TEST_SUITE_P(Scenes, RenderRegression, ::testing::ValuesIn(kCases),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(EmbreeBackend, SameImageForAnyThreadCount) {
  testing::TempDir tmp;
  const Case c{"cloth_threads", false, "embree", 2, 1};
  Image one, two;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = render_case(c, tmp.path() / "one");
  }
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
    two = render_case(c, tmp.path() / "two");
  }
  EXPECT_EQ(one.pixels, two.pixels);
}

}  // namespace kf::render
