// Particle selectors (rows, columns, edges, corners, a rectangle of (i, j), a region of the rest sheet) for
// keyframes and pins, and targets as offsets from the rest sheet; errors name the selector.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/error.h"
#include "scene/particle_selector.h"
#include "scene/scene.h"

namespace kf {
namespace {

// A 5 x 4 sheet, 2 m wide and 1.5 m high, lying in the x-z plane from (1, 0.5, 0).
std::string cloth_scene(const std::string& objective, const std::string& pins = R"("top_corners")") {
  return R"({"time": {"frames": 10},
    "cloth": {"nx": 5, "ny": 4, "width": 2, "height": 1.5, "origin": [1, 0.5, 0], "v_axis": [0, 0, 1],
              "pins": )" + pins + R"(},
    "objectives": [)" + objective + "]}";
}

std::vector<int> selected(const std::string& selector) {
  const Scene s = parse_scene(cloth_scene(R"({"type": "position", "frame": 5, "particles": )" + selector +
                                          R"(, "targets": [[0, 0, 0]]})"),
                              "s.json");
  return s.objectives.at(0).particles;
}

std::string error_of(const std::string& text) {
  try {
    parse_scene(text, "s.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(ParticleSelector, RowsColumnsEdgesCornersRectanglesAndRegions) {
  EXPECT_EQ(selected(R"({"row": 2})"), (std::vector<int>{10, 11, 12, 13, 14}));
  EXPECT_EQ(selected(R"({"column": 4})"), (std::vector<int>{4, 9, 14, 19}));
  EXPECT_EQ(selected(R"({"i": [3, 1], "j": [0, 1]})"), (std::vector<int>{1, 2, 3, 6, 7, 8}));
  EXPECT_EQ(selected(R"({"row": 3, "i": [1, 2]})"), (std::vector<int>{16, 17}));  // keys narrow together
  EXPECT_EQ(selected(R"("top_edge")"), (std::vector<int>{15, 16, 17, 18, 19}));
  EXPECT_EQ(selected(R"("left_edge")"), (std::vector<int>{0, 5, 10, 15}));
  EXPECT_EQ(selected(R"("corners")"), (std::vector<int>{0, 4, 15, 19}));
  EXPECT_EQ(selected(R"("edges")").size(), 14u);  // 2 * 5 + 2 * 4 - 4
  EXPECT_TRUE(selected(R"("all")").empty());       // empty: every particle
  // Rest spacing: 0.5 m along u, 0.5 m along v. A region drawn to a row's exact distance includes it.
  EXPECT_EQ(selected(R"({"u": [0.9, 2], "v": [1, 1.5]})"), (std::vector<int>{12, 13, 14, 17, 18, 19}));
  EXPECT_EQ(selected(R"([3, 1, 3])"), (std::vector<int>{1, 3}));
}

TEST(ParticleSelector, PinsTakeTheSameSelectors) {
  const Scene s = parse_scene(cloth_scene("", R"({"row": 3, "i": [0, 1]})"), "s.json");
  EXPECT_EQ(s.cloth->pins, (std::vector<int>{15, 16}));
  EXPECT_EQ(parse_scene(cloth_scene("", R"("bottom_corners")"), "s.json").cloth->pins, (std::vector<int>{0, 4}));
}

TEST(ParticleSelector, OffsetsFromTheRestSheet) {
  // Lift the middle row 30 cm: one rigid offset for the set.
  const Scene s = parse_scene(cloth_scene(R"({"type": "position", "frame": 5, "particles": {"row": 2},
                                              "offset": [0, 0.3, 0]})"),
                              "s.json");
  const auto& t = std::get<PositionKeyframe>(s.objectives[0].kind).targets;
  ASSERT_EQ(t.size(), 5u);
  for (int k = 0; k < 5; ++k) {
    EXPECT_NEAR((t[size_t(k)] - Vec3(1 + 0.5 * k, 0.8, 1.0)).norm(), 0, 1e-15) << k;
    EXPECT_NEAR((t[size_t(k)] - rest_position(*s.cloth, 10 + k) - Vec3(0, 0.3, 0)).norm(), 0, 1e-15);
  }
  // One offset per particle.
  const Scene each = parse_scene(cloth_scene(R"({"type": "position", "frame": 5, "particles": "bottom_corners",
                                                 "offset": [[0, 1, 0], [0, 2, 0]], "from": "rest"})"),
                                 "s.json");
  const auto& te = std::get<PositionKeyframe>(each.objectives[0].kind).targets;
  EXPECT_NEAR((te[0] - Vec3(1, 1.5, 0)).norm(), 0, 1e-15);
  EXPECT_NEAR((te[1] - Vec3(3, 2.5, 0)).norm(), 0, 1e-15);
  // A centre of mass: the rest centre of the set, moved.
  const Scene com = parse_scene(cloth_scene(R"({"type": "center_of_mass", "frame": 5, "particles": "left_edge",
                                                "offset": [0.1, -0.2, 0]})"),
                                "s.json");
  EXPECT_NEAR((std::get<CenterOfMassKeyframe>(com.objectives[0].kind).target - Vec3(1.1, 0.3, 0.75)).norm(), 0,
              1e-15);
}

TEST(ParticleSelector, ErrorsNameTheSelector) {
  const std::string empty = error_of(cloth_scene(R"({"type": "position", "frame": 5, "particles": {"u": [2.2, 3]},
                                                     "targets": [[0, 0, 0]]})"));
  EXPECT_EQ(empty, "s.json: /objectives/0/particles: selects no particle of the 5 x 4 sheet ({\"u\":[2.2,3]}; i runs "
                   "0 … 4, j 0 … 3, u 0 … 2 m, v 0 … 1.5 m)");
  EXPECT_EQ(error_of(cloth_scene("", R"({"i": [3, 4], "u": [0, 0.4]})")),
            "s.json: /cloth/pins: selects no particle of the 5 x 4 sheet ({\"i\":[3,4],\"u\":[0,0.4]}; i runs 0 … "
            "4, j 0 … 3, u 0 … 2 m, v 0 … 1.5 m)");
  EXPECT_NE(error_of(cloth_scene(R"({"type": "position", "frame": 5, "particles": {"row": 4}, "targets": [[0, 0, 0]]})"))
                .find("s.json: /objectives/0/particles/row: expected an integer in [0, 3], got 4"),
            std::string::npos);
  EXPECT_NE(error_of(cloth_scene(R"({"type": "position", "frame": 5, "particles": {"rows": 1}, "targets": [[0, 0, 0]]})"))
                .find("s.json: /objectives/0/particles/rows: unknown key"),
            std::string::npos);
  EXPECT_NE(error_of(cloth_scene(R"({"type": "position", "frame": 5, "particles": {}, "targets": [[0, 0, 0]]})"))
                .find("s.json: /objectives/0/particles: expected a selector with at least one of"),
            std::string::npos);
  EXPECT_NE(error_of(cloth_scene(R"({"type": "position", "frame": 5, "particles": "middle", "targets": [[0, 0, 0]]})"))
                .find("s.json: /objectives/0/particles: expected one of \"all\", \"top_edge\""),
            std::string::npos);
  EXPECT_NE(error_of(cloth_scene(R"({"type": "position", "frame": 5, "particles": {"row": 1}, "offset": [[0, 0, 0], [0, 1, 0]]})"))
                .find("s.json: /objectives/0/offset: expected [dx, dy, dz] (the whole set moved rigidly) or one offset per particle (5), got 2"),
            std::string::npos);
  EXPECT_NE(error_of(cloth_scene(R"({"type": "position", "frame": 5, "offset": [0, 0, 0], "targets": [[0, 0, 0]]})"))
                .find("s.json: /objectives/0/offset: expected either \"targets\" or \"offset\", not both"),
            std::string::npos);
  const std::string flock = R"({"time": {"frames": 10}, "flock": {"agents": 6},
    "objectives": [{"type": "position", "frame": 5, "particles": )";
  EXPECT_NE(error_of(flock + R"({"row": 1}, "targets": [[0, 0, 0]]}]})")
                .find("s.json: /objectives/0/particles: expected particle indices or \"all\""),
            std::string::npos);
  EXPECT_NE(error_of(flock + R"("all", "offset": [0, 0, 1]}]})").find("s.json: /objectives/0/offset: expected absolute"),
            std::string::npos);
}

}  // namespace
}  // namespace kf
