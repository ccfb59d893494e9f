// A flock's shape keyframe as a ring (the outer circle with the inner one as a hole) and with "holes" cut
// from any outline; bad rings and holes name their field.
#include <gtest/gtest.h>

#include "core/error.h"
#include "scene/scene.h"

namespace kf {
namespace {

std::string flock_scene(const std::string& shape) {
  return R"({"time": {"frames": 10}, "flock": {"agents": 4}, "objectives": [{"type": "shape", "frame": 10, )" + shape +
         "}]}";
}

const ShapeKeyframe& shape_of(const Scene& s) { return std::get<ShapeKeyframe>(s.objectives.at(0).kind); }

TEST(ShapeRing, IsTheOuterCircleWithTheInnerOneAsAHole) {
  const Scene s = parse_scene(
      flock_scene(R"("ring": {"center": [2, -1], "inner_radius": 1.5, "outer_radius": 4, "segments": 24})"), "r.json");
  const ShapeKeyframe& k = shape_of(s);
  ASSERT_EQ(k.polygon.size(), 24u);
  ASSERT_EQ(k.holes.size(), 1u);
  ASSERT_EQ(k.holes[0].size(), 24u);
  for (const Vec2& q : k.polygon) EXPECT_NEAR((q - Vec2(2, -1)).norm(), 4.0, 1e-12);
  for (const Vec2& q : k.holes[0]) EXPECT_NEAR((q - Vec2(2, -1)).norm(), 1.5, 1e-12);
  const Scene d = parse_scene(flock_scene(R"("ring": {"center": [0, 0], "inner_radius": 1, "outer_radius": 2})"), "d.json");
  EXPECT_EQ(shape_of(d).polygon.size(), 64u);  // the default
}

TEST(ShapeRing, HolesAreCutFromAPolygonOrACircle) {
  const Scene s = parse_scene(flock_scene(R"("polygon": [[0, 0], [10, 0], [10, 4], [0, 4]],
      "holes": [{"polygon": [[1, 1], [3, 1], [3, 3], [1, 3]]}, {"circle": {"center": [7, 2], "radius": 1, "segments": 8}}])"),
                              "h.json");
  const ShapeKeyframe& k = shape_of(s);
  ASSERT_EQ(k.holes.size(), 2u);
  EXPECT_EQ(k.holes[0].size(), 4u);
  EXPECT_EQ(k.holes[1].size(), 8u);
  const Scene r = parse_scene(flock_scene(R"("ring": {"center": [0, 0], "inner_radius": 1, "outer_radius": 4},
      "holes": [{"circle": {"center": [2.5, 0], "radius": 0.5}}])"), "rh.json");
  EXPECT_EQ(shape_of(r).holes.size(), 2u);  // the ring's own and the one given
}

TEST(ShapeRing, BadRingsAndHolesNameTheField) {
  auto message = [](const std::string& shape) {
    try {
      parse_scene(flock_scene(shape), "bad.json");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(message(R"("ring": {"center": [0, 0], "inner_radius": 2, "outer_radius": 2})"),
            "bad.json: /objectives/0/ring/outer_radius: expected more than \"inner_radius\"");
  EXPECT_NE(message(R"("ring": {"center": [0, 0], "outer_radius": 2})").find("/objectives/0/ring/inner_radius"),
            std::string::npos);
  EXPECT_NE(message(R"("ring": {"center": [0, 0], "inner_radius": 1, "outer_radius": 2}, "circle": {"center": [0, 0], "radius": 1})")
                .find("one of"),
            std::string::npos);
  const std::string square = R"("polygon": [[0, 0], [4, 0], [4, 4], [0, 4]], )";
  EXPECT_EQ(message(square + R"("holes": [{"polygon": [[1, 1], [5, 1], [1, 2]]}])"),
            "bad.json: /objectives/0/holes: hole 0 has a point outside the outer shape");
  EXPECT_EQ(message(square + R"("holes": [{"circle": {"center": [1, 1], "radius": 0.5}}, {"circle": {"center": [1.5, 1], "radius": 0.5}}])"),
            "bad.json: /objectives/0/holes: hole 1 overlaps hole 0");
  EXPECT_EQ(message(square + R"("holes": [{"circle": {"center": [2, 2], "radius": 1.5}}, {"circle": {"center": [2, 2], "radius": 0.5}}])"),
            "bad.json: /objectives/0/holes: hole 1 overlaps hole 0");  // one inside the other
  EXPECT_NE(message(square + R"("holes": [{"circle": {"center": [2, 2], "radius": 1}, "polygon": [[1, 1], [2, 1], [1, 2]]}])")
                .find("/objectives/0/holes/0: expected one of"),
            std::string::npos);
  EXPECT_NE(message(square + R"("holes": [{"circle": {"center": [2, 2], "radius": 1}, "radius": 3}])")
                .find("/objectives/0/holes/0/radius: unknown key"),
            std::string::npos);
}

}  // namespace
}  // namespace kf
