// keyframe compare: metrics with known answers, identical and noisy frames, a visible change with its
// diff images, the reports, --update, and each kind of bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "render/compare/compare_frames.h"
#include "render/image/diff_heatmap.h"
#include "render/image/image_metrics.h"
#include "render/render_run.h"
#include "png_files.h"
#include "synthetic_runs.h"

namespace kf::render {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Renders every frame of a small flock run into RUN/frames with `backend` at `spp`, then moves the frames
// to `frames` so that several renders of one run can sit side by side.
fs::path render_frames(const fs::path& run, const fs::path& frames, const std::string& backend, int spp) {
  RenderRequest r;
  r.run_dir = run;
  r.backend = backend;
  r.width = 96;
  r.height = 72;
  r.spp = spp;
  EXPECT_EQ(render_run(r), 6);
  fs::rename(run / "frames", frames);
  return frames;
}

TEST(ImageMetrics, KnownAnswersOnTwoByTwo) {
  Image a(2, 2, 3), b(2, 2, 4);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 2; ++x) b.at(x, y)[3] = 255;  // alpha is ignored
  ImageMetrics m = image_metrics(a, b, 0);
  EXPECT_EQ(m.max_abs, 0);
  EXPECT_EQ(m.rmse, 0.0);
  EXPECT_TRUE(std::isinf(m.psnr));
  b.at(1, 0)[2] = 10;  // one channel of one pixel, 10 levels
  m = image_metrics(a, b, 0);
  EXPECT_EQ(m.max_abs, 10);
  EXPECT_DOUBLE_EQ(m.mean_abs, 10.0 / 12.0);
  EXPECT_DOUBLE_EQ(m.rmse, std::sqrt(100.0 / 12.0));
  EXPECT_NEAR(m.psnr, 20.0 * std::log10(255.0 / std::sqrt(100.0 / 12.0)), 1e-12);
  EXPECT_DOUBLE_EQ(m.over_fraction, 0.25);
  EXPECT_DOUBLE_EQ(image_metrics(a, b, 10).over_fraction, 0.0);  // within the tolerance
  EXPECT_THROW(image_metrics(a, Image(2, 3, 3), 0), std::invalid_argument);

  const Image heat = diff_heatmap(a, b, 0);
  EXPECT_EQ(heat.at(0, 0)[0], 0);
  EXPECT_GT(heat.at(1, 0)[0], 100);  // the changed pixel glows
  EXPECT_EQ(diff_heatmap(a, b, 10).at(1, 0)[0], 40);  // within the tolerance: dark grey
  EXPECT_EQ(side_by_side(a, b, heat).width, 3 * 2 + 2 * 4);
}

TEST(Compare, IdenticalFramesPassAndReportEveryFrame) {
  testing::TempDir tmp;
  const auto run = testing::make_flock_run(tmp.path() / "flock");
  const auto ref = render_frames(run, tmp.path() / "ref", "osmesa", 0);
  render_frames(run, run / "frames", "osmesa", 0);  // a second render of the same run
  CompareRequest r;
  r.actual = run;
  r.reference = ref;
  const CompareResult res = compare_frames(r);
  ASSERT_EQ(res.frames.size(), 6u);
  EXPECT_EQ(res.failed, 0);
  for (const auto& f : res.frames) EXPECT_EQ(f.metrics.max_abs, 0) << f.name;
  EXPECT_EQ(res.out_dir, fs::weakly_canonical(run) / "compare");
  const auto j = nlohmann::json::parse(slurp(res.json));
  EXPECT_EQ(j["frames_compared"], 6);
  EXPECT_EQ(j["frames_failed"], 0);
  EXPECT_TRUE(j["frames"][0]["psnr_db"].is_null());  // identical
  const std::string junit = slurp(res.junit);
  EXPECT_NE(junit.find("tests=\"6\" failures=\"0\""), std::string::npos) << junit;
  EXPECT_NE(junit.find("name=\"frame_0005.png\""), std::string::npos);
}

TEST(Compare, EmbreeNoiseFailsByDefaultAndPassesWithTheNoiseOption) {
  testing::TempDir tmp;
  const auto run = testing::make_flock_run(tmp.path() / "flock");
  const auto ref = render_frames(run, tmp.path() / "ref", "embree", 4);
  const auto actual = render_frames(run, tmp.path() / "spp16", "embree", 16);
  CompareRequest r;
  r.actual = actual;
  r.reference = ref;
  r.out_dir = tmp.path() / "report";
  CompareResult res = compare_frames(r);
  EXPECT_EQ(res.failed, 6);  // sampling noise is a difference when identical frames are expected
  for (const auto& f : res.frames) EXPECT_GT(f.metrics.max_abs, 0) << f.name;
  r.thresholds = noise_thresholds();
  res = compare_frames(r);
  for (const auto& f : res.frames) {
    EXPECT_TRUE(f.pass) << f.name << ": " << f.why;
    EXPECT_GT(f.metrics.over_fraction + f.metrics.mean_abs, 0.0);
  }
  EXPECT_EQ(res.failed, 0);
  EXPECT_FALSE(fs::exists(tmp.path() / "report/frame_0000_diff.png"));  // the first run's diffs are gone
}

TEST(Compare, VisibleChangeFailsEvenWithNoiseAndWritesItsDiff) {
  testing::TempDir tmp;
  const auto run = testing::make_flock_run(tmp.path() / "flock");
  const auto ref = render_frames(run, tmp.path() / "ref", "embree", 4);
  const auto actual = render_frames(run, tmp.path() / "spp16", "embree", 16);
  // Frame 2 shows frame 5's agents: the flock has turned by 1.2 rad about the origin.
  fs::copy_file(actual / "frame_0005.png", actual / "frame_0002.png", fs::copy_options::overwrite_existing);
  CompareRequest r;
  r.actual = actual;
  r.reference = ref;
  r.thresholds = noise_thresholds();
  const CompareResult res = compare_frames(r);
  EXPECT_EQ(res.failed, 1);
  const FrameResult& f = res.frames[2];
  ASSERT_EQ(f.name, "frame_0002.png");
  EXPECT_FALSE(f.pass);
  EXPECT_FALSE(f.why.empty());
  EXPECT_GT(f.metrics.over_fraction, 2 * noise_thresholds().max_fraction);  // not a near miss
  const Image heat = read_png(res.out_dir / "frame_0002_diff.png");
  EXPECT_EQ(heat.width, 96);
  const Image side = read_png(res.out_dir / "frame_0002_side.png");
  EXPECT_EQ(side.width, 3 * 96 + 8);
  EXPECT_FALSE(fs::exists(res.out_dir / "frame_0001_diff.png"));  // passing frames get none
  const auto j = nlohmann::json::parse(slurp(res.json));
  EXPECT_EQ(j["frames"][2]["pass"], false);
  EXPECT_EQ(j["frames"][2]["diff"], "frame_0002_diff.png");
  EXPECT_NE(slurp(res.junit).find("<failure message="), std::string::npos);
}

TEST(Compare, UpdateReplacesReferencesOnlyWhenAsked) {
  testing::TempDir tmp;
  const auto run = testing::make_flock_run(tmp.path() / "flock");
  const auto ref = render_frames(run, tmp.path() / "ref", "osmesa", 0);
  const auto actual = render_frames(run, tmp.path() / "new", "osmesa", 0);
  fs::copy_file(actual / "frame_0004.png", actual / "frame_0002.png", fs::copy_options::overwrite_existing);
  const std::string before = slurp(ref / "frame_0002.png");
  CompareRequest r;
  r.actual = actual;
  r.reference = ref;
  EXPECT_EQ(compare_frames(r).failed, 1);
  EXPECT_EQ(slurp(ref / "frame_0002.png"), before);  // a failing comparison leaves references alone
  r.update = true;
  const CompareResult updated = compare_frames(r);
  EXPECT_EQ(updated.updated, 1);  // only the changed frame is rewritten
  EXPECT_EQ(slurp(ref / "frame_0002.png"), slurp(actual / "frame_0002.png"));
  r.update = false;
  EXPECT_EQ(compare_frames(r).failed, 0);

  // --update creates a reference directory from nothing.
  r.reference = tmp.path() / "fresh";
  EXPECT_THROW(compare_frames(r), InputError);
  r.update = true;
  const CompareResult fresh = compare_frames(r);
  EXPECT_EQ(fresh.updated, 6);
  EXPECT_EQ(fresh.added, 6);  // new frames are neither passes nor failures
  EXPECT_EQ(fresh.failed, 0);
  EXPECT_NE(slurp(fresh.junit).find("<skipped message="), std::string::npos);
  EXPECT_TRUE(fs::exists(tmp.path() / "fresh/frame_0005.png"));
}

// The one-line message of the InputError that comparing `actual` with `ref` throws.
std::string input_error(const fs::path& actual, const fs::path& ref) {
  CompareRequest r;
  r.actual = actual;
  r.reference = ref;
  r.out_dir = actual.parent_path() / "report";
  try {
    compare_frames(r);
  } catch (const InputError& e) {
    EXPECT_FALSE(fs::exists(r.out_dir)) << "bad input must stop before anything is written";
    return e.what();
  }
  ADD_FAILURE() << "expected an InputError";
  return {};
}

TEST(Compare, BadInputIsOneClearError) {
  testing::TempDir tmp;
  const auto run = testing::make_flock_run(tmp.path() / "flock");
  const auto ref = render_frames(run, tmp.path() / "ref", "osmesa", 0);
  const fs::path a = tmp.path() / "a";
  fs::copy(ref, a);

  fs::remove(a / "frame_0003.png");  // missing on the actual side
  std::string e = input_error(a, ref);
  EXPECT_NE(e.find("frame_0003.png: missing"), std::string::npos) << e;
  fs::copy_file(ref / "frame_0003.png", a / "frame_0003.png");

  fs::copy_file(ref / "frame_0003.png", a / "frame_0006.png");  // missing on the reference side
  e = input_error(a, ref);
  EXPECT_NE(e.find("missing reference for"), std::string::npos) << e;
  fs::remove(a / "frame_0006.png");

  write_png(a / "frame_0001.png", Image(95, 72, 3));  // a size mismatch
  e = input_error(a, ref);
  EXPECT_NE(e.find("95x72 pixels, but the reference"), std::string::npos) << e;
  EXPECT_NE(e.find("96x72"), std::string::npos) << e;
  fs::copy_file(ref / "frame_0001.png", a / "frame_0001.png", fs::copy_options::overwrite_existing);

  const std::string bytes = slurp(ref / "frame_0004.png");  // a truncated PNG
  std::ofstream(a / "frame_0004.png", std::ios::binary | std::ios::trunc) << bytes.substr(0, bytes.size() / 2);
  e = input_error(a, ref);
  EXPECT_NE(e.find("frame_0004.png: corrupt or truncated PNG"), std::string::npos) << e;
  std::ofstream(a / "frame_0004.png", std::ios::binary | std::ios::trunc) << "not a png at all";
  e = input_error(a, ref);
  EXPECT_NE(e.find("frame_0004.png: not a PNG file"), std::string::npos) << e;
  fs::copy_file(ref / "frame_0004.png", a / "frame_0004.png", fs::copy_options::overwrite_existing);

  fs::create_directories(tmp.path() / "empty");  // an empty directory, either side
  e = input_error(tmp.path() / "empty", ref);
  EXPECT_NE(e.find("no PNG frames to compare"), std::string::npos) << e;
  e = input_error(a, tmp.path() / "empty");
  EXPECT_NE(e.find("no PNG reference frames"), std::string::npos) << e;
  e = input_error(tmp.path() / "nowhere", ref);
  EXPECT_NE(e.find("not a directory"), std::string::npos) << e;

  // Repaired, the same directories pass.
  CompareRequest r;
  r.actual = a;
  r.reference = ref;
  EXPECT_EQ(compare_frames(r).failed, 0);
}

TEST(Compare, InterlacedFramesWithTheSamePixelsPass) {
  testing::TempDir tmp;
  const fs::path ref = tmp.path() / "ref", actual = tmp.path() / "actual";
  fs::create_directories(ref);
  fs::create_directories(actual);
  Image img(40, 30, 3);
  for (size_t i = 0; i < img.pixels.size(); ++i) img.pixels[i] = uint8_t((i * 37) % 251);
  write_png(ref / "frame_0000.png", img);
  write_interlaced_png(actual / "frame_0000.png", img);
  CompareRequest r;
  r.actual = actual;
  r.reference = ref;
  const CompareResult res = compare_frames(r);
  EXPECT_EQ(res.failed, 0);
  EXPECT_EQ(res.frames.at(0).metrics.max_abs, 0);

  // A truncated interlaced frame is refused, and --update does not copy it into the references.
  const std::string bytes = slurp(actual / "frame_0000.png");
  std::ofstream(actual / "frame_0000.png", std::ios::binary | std::ios::trunc) << bytes.substr(0, bytes.size() - 40);
  const std::string before = slurp(ref / "frame_0000.png");
  r.update = true;
  EXPECT_THROW(compare_frames(r), InputError);
  EXPECT_EQ(slurp(ref / "frame_0000.png"), before);
}

TEST(Compare, AlphaDifferenceFailsTheFrame) {
  testing::TempDir tmp;
  const fs::path ref = tmp.path() / "ref", actual = tmp.path() / "actual";
  fs::create_directories(ref);
  fs::create_directories(actual);
  Image opaque(20, 10, 3), transparent(20, 10, 4);  // same colour, one fully transparent
  write_png(ref / "frame_0000.png", opaque);
  write_png(actual / "frame_0000.png", transparent);
  CompareRequest r;
  r.actual = actual;
  r.reference = ref;
  r.thresholds = noise_thresholds();
  const CompareResult res = compare_frames(r);
  EXPECT_EQ(res.failed, 1);
  EXPECT_EQ(res.frames.at(0).metrics.max_abs, 255);
  EXPECT_EQ(res.frames.at(0).why, "100% of pixels differ by more than 48 levels (allowed 1%, largest difference 255)");
  // Opaque alpha against no alpha is the same frame.
  for (size_t i = 3; i < transparent.pixels.size(); i += 4) transparent.pixels[i] = 255;
  write_png(actual / "frame_0000.png", transparent);
  r.thresholds = {};
  EXPECT_EQ(compare_frames(r).failed, 0);
}

TEST(Compare, SizeMismatchIsFoundFromTheHeaders) {
  // The actual frame claims 8000x10 pixels but holds none: the mismatch is reported without decoding it,
  // and a header past the size limit is refused before any pixel is allocated.
  testing::TempDir tmp;
  const fs::path ref = tmp.path() / "ref", actual = tmp.path() / "actual";
  fs::create_directories(ref);
  fs::create_directories(actual);
  write_png(ref / "frame_0000.png", Image(64, 48, 3));
  write_header_only_png(actual / "frame_0000.png", 8000, 10);
  std::string e = input_error(actual, ref);
  EXPECT_EQ(e, (actual / "frame_0000.png").string() + ": 8000x10 pixels, but the reference " +
                   (ref / "frame_0000.png").string() + " has 64x48");
  write_header_only_png(actual / "frame_0000.png", 20000, 20000);
  e = input_error(actual, ref);
  EXPECT_NE(e.find("20000x20000 pixels, larger than keyframe reads"), std::string::npos) << e;
}

}  // namespace
}  // namespace kf::render
