// A flock's shape keyframe given as a circle: the regular polygon through its points, counter-clockwise
// in (x, z); "polygon" and "circle" exclude each other.
#include <gtest/gtest.h>

#include "core/error.h"
#include "scene/scene.h"

namespace kf {
namespace {

std::string flock_scene(const std::string& shape) {
  return R"({"time": {"frames": 10}, "flock": {"agents": 4}, "objectives": [{"type": "shape", "frame": 10, )" + shape +
         "}]}";
}

TEST(ShapeCircle, IsARegularPolygonOnTheCircleCounterClockwiseInXZ) {
  const Scene s = parse_scene(flock_scene(R"("circle": {"center": [3, -1], "radius": 2, "segments": 12})"), "c.json");
  const auto& poly = std::get<ShapeKeyframe>(s.objectives.at(0).kind).polygon;
  ASSERT_EQ(poly.size(), 12u);
  double area2 = 0;
  for (size_t i = 0; i < poly.size(); ++i) {
    EXPECT_NEAR((poly[i] - Vec2(3, -1)).norm(), 2.0, 1e-12);
    const Vec2& a = poly[i];
    const Vec2& b = poly[(i + 1) % poly.size()];
    area2 += a.x() * b.y() - b.x() * a.y();
  }
  EXPECT_GT(area2, 0.0);  // counter-clockwise with x right and z up on paper
  EXPECT_NEAR(0.5 * area2, 0.5 * 12 * 4 * std::sin(2 * M_PI / 12), 1e-9);
  const Scene d = parse_scene(flock_scene(R"("circle": {"center": [0, 0], "radius": 1})"), "d.json");
  EXPECT_EQ(std::get<ShapeKeyframe>(d.objectives.at(0).kind).polygon.size(), 64u);  // the default
}

TEST(ShapeCircle, BadCirclesNameTheField) {
  auto message = [](const std::string& shape) {
    try {
      parse_scene(flock_scene(shape), "bad.json");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message(R"("circle": {"center": [0, 0, 0], "radius": 1})").find("/objectives/0/circle/center"),
            std::string::npos);
  EXPECT_NE(message(R"("circle": {"center": [0, 0]})").find("/objectives/0/circle/radius"), std::string::npos);
  EXPECT_NE(message(R"("circle": {"center": [0, 0], "radius": 1, "segments": 2})").find("segments"), std::string::npos);
  EXPECT_NE(message(R"("circle": {"center": [0, 0], "radius": 1}, "polygon": [[0,0],[1,0],[0,1]])").find("one of"),
            std::string::npos);
  EXPECT_NE(message(R"("margin": 0.1)").find("one of"), std::string::npos);
}

}  // namespace
}  // namespace kf
