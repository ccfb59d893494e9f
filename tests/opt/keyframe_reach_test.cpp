// Keyframes a pinned sheet cannot reach are named before optimising.
#include <gtest/gtest.h>

#include <string>

#include "opt/keyframes/keyframe_reach.h"
#include "scene/scene.h"

namespace kf {
namespace {

// A 1 m sheet hanging from its top corners at (0, 1, 0) and (1, 1, 0).
std::string hanging_sheet(const std::string& objectives) {
  return R"({"time": {"fps": 30, "frames": 10},
    "cloth": {"nx": 5, "ny": 5, "width": 1, "height": 1, "pins": "top_corners"},
    "objectives": [)" + objectives + "]}";
}

TEST(ReachCheck, TargetBeyondThePinsRadiusIsNamed) {
  // Particle 0 (bottom left, 1 m below its pin) asked to be 2 m below the pin.
  const Scene s = parse_scene(hanging_sheet(R"({"type": "center_of_mass", "frame": 10, "target": [0.5, 0.5, 0]},
      {"type": "position", "frame": 5, "particles": [0], "targets": [[0, -1, 0]]})"), "far.json");
  const auto w = unreachable_keyframes(s);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0].rfind("far.json: /objectives/1: particle 0's target at frame 5 is 2.000 m from pin 20, which holds "
                       "it within 1.000 m (its rest distance): out of reach", 0), 0u) << w[0];
}

TEST(ReachCheck, CentreOfMassBeyondEveryParticlesReachIsNamed) {
  const Scene s = parse_scene(hanging_sheet(R"({"type": "center_of_mass", "frame": 10, "target": [0.5, -3, 0.2]})"),
                              "com.json");
  const auto w = unreachable_keyframes(s);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NE(w[0].find("com.json: /objectives/0: the centre-of-mass target at frame 10 is "), std::string::npos) << w[0];
  EXPECT_NE(w[0].find("out of reach"), std::string::npos) << w[0];
}

TEST(ReachCheck, ReachableTargetsAndUnpinnedSheetsAreQuiet) {
  // Swinging the sheet sideways keeps every particle within its rest distance of both pins.
  EXPECT_TRUE(unreachable_keyframes(parse_scene(hanging_sheet(R"({"type": "center_of_mass", "frame": 10, "target": [0.5, 0.6, 0.4]},
      {"type": "position", "frame": 5, "particles": [0], "targets": [[0, 0.1, 0.4]]})"), "near.json")).empty());
  // A pinned particle's own target written rounded (0.1 mm off) is where its pin holds it; 10 cm off is not.
  EXPECT_TRUE(unreachable_keyframes(parse_scene(hanging_sheet(R"({"type": "position", "frame": 5, "particles": [20],
      "targets": [[0.0001, 1, 0]]})"), "pinned.json")).empty());
  EXPECT_EQ(unreachable_keyframes(parse_scene(hanging_sheet(R"({"type": "position", "frame": 5, "particles": [20],
      "targets": [[0, 1.1, 0]]})"), "pinned.json")).size(), 1u);
  std::string free = hanging_sheet(R"({"type": "center_of_mass", "frame": 10, "target": [0.5, -30, 0]})");
  free.replace(free.find("\"top_corners\""), 13, "\"none\"");
  EXPECT_TRUE(unreachable_keyframes(parse_scene(free, "free.json")).empty());
}

}  // namespace
}  // namespace kf
