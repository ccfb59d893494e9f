// The height keyframe (the mean height of some particles) through the binary: simulate reports and prints
// it, optimize lifts a hanging sheet towards it, and a flock or a missing height is refused in one line.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "../support/cli_test.h"

namespace kf {
namespace {
using namespace cli_test;

class HeightKeyframe : public TempDirTest {};

// A 5 x 5 sheet pinned at its top corners (at y = 1), hanging to y = 0 at rest; the bottom row (particles
// 0..4) asked up to 0.6 m at frame 10.
std::string hanging(const std::string& objective) {
  return R"({"seed": 3, "time": {"fps": 30, "frames": 10},
  "cloth": {"nx": 5, "ny": 5, "width": 1, "height": 1, "pins": "top_corners"},
  "objectives": [)" + objective + R"(],
  "controls": {"kind": "per_frame", "alpha": 0.0001},
  "optimizer": {"max_evaluations": 12},
  "render": {"width": 64, "height": 48}})";
}
const char* kLift = R"({"type": "height", "frame": 10, "particles": [0, 1, 2, 3, 4], "height": 0.6})";

TEST_F(HeightKeyframe, SimulateMeasuresAndPrintsTheMeanHeight) {
  write("cloth.json", hanging(kLift));
  const auto r = run_keyframe("simulate cloth.json --out run", dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  const Json report = Json::parse(read_text(dir_ / "run/report.json"));
  const Json& m = report.at("measures").at(0);
  EXPECT_EQ(m.at("type"), "height");
  EXPECT_EQ(m.at("frame"), 10);
  const double mean = m.at("mean_height").get<double>();
  EXPECT_LT(mean, 0.3);  // the bottom row hangs near the ground
  EXPECT_NEAR(m.at("error").get<double>(), 0.6 - mean, 1e-12);
  const Json& k = report.at("keyframe_errors").at(0);
  EXPECT_EQ(k.at("name"), "height@10");
  EXPECT_EQ(k.at("tolerance"), "1.00 cm");
  EXPECT_FALSE(k.at("met").get<bool>());
  char line[160];
  std::snprintf(line, sizeof line, "\nheight@10: %.2f cm from its target height (tolerance 1.00 cm, not met)\n",
                100 * (0.6 - mean));
  EXPECT_NE(r.output.find(line), std::string::npos) << r.output;
}

TEST_F(HeightKeyframe, OptimizeLiftsTheSheetTowardsIt) {
  write("cloth.json", hanging(kLift));
  const auto r = run_keyframe("optimize cloth.json --out run --quiet", dir_);
  ASSERT_TRUE(r.code == 0 || r.code == kExitNotReached) << r.output;
  const Json report = Json::parse(read_text(dir_ / "run/report.json"));
  const Json& k = report.at("keyframe_errors").at(0);
  EXPECT_EQ(k.at("name"), "height@10");
  // The run's miss is a small part of the hanging sheet's, and report.json's verdict is its exit code's.
  EXPECT_LT(k.at("miss_after").get<double>(), 0.25 * k.at("miss_before").get<double>()) << report.dump();
  EXPECT_EQ(r.code == 0, k.at("met").get<bool>()) << r.output;
}

TEST_F(HeightKeyframe, AFlockOrAMissingHeightIsRefusedInOneLine) {
  struct Bad {
    std::string scene, pointer, expected;
  };
  const std::vector<Bad> cases = {
      {R"({"time": {"frames": 4}, "flock": {"agents": 4},
           "objectives": [{"type": "height", "frame": 4, "height": 1}]})",
       "/objectives/0/type", "keyframes are for cloth"},
      {hanging(R"({"type": "height", "frame": 10})"), "/objectives/0/height", "height"},
      {hanging(R"({"type": "height", "frame": 10, "height": "up"})"), "/objectives/0/height", "number"},
  };
  for (const Bad& c : cases) {
    write("bad.json", c.scene);
    const auto r = run_keyframe("simulate bad.json --out bad", dir_);
    EXPECT_EQ(r.code, kExitInput) << r.output;
    EXPECT_NE(r.output.find("bad.json"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(c.pointer), std::string::npos) << c.pointer << "\n" << r.output;
    EXPECT_NE(r.output.find(c.expected), std::string::npos) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_FALSE(fs::exists(dir_ / "bad")) << "partial output";
  }
}

}  // namespace
}  // namespace kf
