// keyframe inspect SCENE on a flock with shape keyframes: each shape's bounds on the ground, area less its
// holes and how many agents it holds at the flock's spacing, so a misplaced or mirrored drawing shows
// before a run.
#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>

#include "../reliability/cli_harness.h"

namespace kf {
namespace {
using reliability::run_keyframe;
using reliability::TempDirTest;

class InspectShapes : public TempDirTest {};

const char* kScene = R"({"time": {"frames": 10}, "flock": {"agents": 20, "avoidance": {"radius": 1.5}},
  "objectives": [
    {"type": "shape", "frame": 10, "polygon": [[0, 0], [4, 0], [4, 4], [0, 4]],
     "holes": [{"polygon": [[1, 1], [2, 1], [2, 2], [1, 2]]}]},
    {"type": "center_of_mass", "frame": 5, "target": [0, 0, 0]},
    {"type": "shape", "frame": 8, "svg_path": {"d": "M 0 0 H 2 V 1 H 0 Z", "offset": [1, 2]}}]})";

TEST_F(InspectShapes, EachShapeLineGivesBoundsAreaHolesAndAgentsItHolds) {
  write("s.json", kScene);
  const auto r = run_keyframe("inspect s.json", dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  // 15 m² at 1.5 m apart: 15 / (sqrt(3)/2 * 2.25) = 7.7 agents packed hexagonally.
  EXPECT_NE(r.output.find("\nshape@10: x 0 … 4 m, z 0 … 4 m, area 15 m², 1 hole; holds 7 agents 1.5 m apart (the "
                          "flock has 20)\n"),
            std::string::npos)
      << r.output;
  // An SVG path lands at offset + (px, py): y down the drawing is z toward the viewer.
  EXPECT_NE(r.output.find("\nshape@8: x 1 … 3 m, z 2 … 3 m, area 2 m², 0 holes; holds 1 agent 1.5 m apart (the "
                          "flock has 20)\n"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("center_of_mass@"), std::string::npos) << r.output;
}

TEST_F(InspectShapes, JsonOutputStaysOneDocument) {
  write("s.json", kScene);
  const auto r = run_keyframe("inspect s.json --json", dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output);
  EXPECT_EQ(j["flock"]["agents"], 20);
}

}  // namespace
}  // namespace kf
