// A flock moves on the ground: position and centre-of-mass targets off it (y != 0) are refused, naming the
// field, since no control can ever meet them.
#include <gtest/gtest.h>

#include <string>

#include "core/error.h"
#include "scene/scene.h"

namespace kf {
namespace {

std::string flock_with(const std::string& objective) {
  return R"({"time": {"frames": 10}, "flock": {"agents": 4}, "objectives": [)" + objective + "]}";
}

std::string error_of(const std::string& text) {
  try {
    parse_scene(text, "f.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(FlockGroundTargets, OffTheGroundIsRefusedNamingTheField) {
  EXPECT_EQ(error_of(flock_with(R"({"type": "position", "frame": 5, "particles": [0, 1],
                                    "targets": [[1, 0, 2], [3, 0.5, 1]]})")),
            "f.json: /objectives/0/targets/1: expected a point on the ground, y = 0 (a flock moves on the ground "
            "and cannot reach y = 0.5)");
  EXPECT_EQ(error_of(flock_with(R"({"type": "center_of_mass", "frame": 5, "target": [0, -2, 0]})")),
            "f.json: /objectives/0/target: expected a point on the ground, y = 0 (a flock moves on the ground and "
            "cannot reach y = -2.0)");
}

TEST(FlockGroundTargets, OnTheGroundAndVelocitiesAndClothAreAccepted) {
  EXPECT_EQ(error_of(flock_with(R"({"type": "position", "frame": 5, "targets": [[1, 0, 2]]})")), "(no error)");
  EXPECT_EQ(error_of(flock_with(R"({"type": "center_of_mass", "frame": 5, "target": [1, 0, 2]})")), "(no error)");
  // A velocity target is not a place; only its vertical part could never be met, and a flock's is zero.
  EXPECT_EQ(error_of(flock_with(R"({"type": "velocity", "frame": 5, "targets": [[1, 0, 0]]})")), "(no error)");
  EXPECT_EQ(error_of(R"({"time": {"frames": 10}, "cloth": {"nx": 3, "ny": 3},
    "objectives": [{"type": "position", "frame": 5, "targets": [[0, 2, 0]]}]})"),
            "(no error)");
}

}  // namespace
}  // namespace kf
