// A flock's shape keyframe read from SVG path data ("svg_path" {"d"} or {"file"}): placed by scale and
// offset with SVG's y-down as z toward the viewer, the largest subpath the outline and the others holes,
// measured by the figure measures, and bad paths named by file, JSON pointer and character.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "../reliability/cli_harness.h"
#include "core/error.h"
#include "core/ground_region.h"
#include "core/trajectory.h"
#include "report/figure_measures.h"
#include "scene/scene.h"

namespace kf {
namespace {

namespace fs = std::filesystem;

std::string flock_scene(const std::string& shape, int agents = 4) {
  return R"({"time": {"frames": 10}, "flock": {"agents": )" + std::to_string(agents) +
         R"(}, "objectives": [{"type": "shape", "frame": 10, )" + shape + "}]}";
}

const ShapeKeyframe& shape_of(const Scene& s) { return std::get<ShapeKeyframe>(s.objectives.at(0).kind); }

std::string message(const std::string& text, const fs::path& file = "bad.json") {
  try {
    parse_scene(text, file);
  } catch (const InputError& e) {
    return e.what();
  }
  return "accepted";
}

// An "L" 4 units tall and 3 wide drawn in SVG's frame (y down): its foot at the bottom right.
const char* kL = "M 0 0 H 1 V 3 H 3 V 4 H 0 Z";

TEST(ShapeSvg, ScaleAndOffsetPlaceThePathWithYAsZ) {
  const Scene s = parse_scene(flock_scene(std::string(R"("svg_path": {"d": ")") + kL +
                                          R"(", "scale": 0.5, "offset": [10, -2]})"),
                              "l.json");
  const ShapeKeyframe& k = shape_of(s);
  const std::vector<Vec2> want = {{10, -2}, {10.5, -2}, {10.5, -0.5}, {11.5, -0.5}, {11.5, 0}, {10, 0}};
  ASSERT_EQ(k.polygon.size(), want.size());
  for (size_t i = 0; i < want.size(); ++i) EXPECT_LT((k.polygon[i] - want[i]).norm(), 1e-12) << i;
  EXPECT_TRUE(k.holes.empty());
  // The foot is at the largest z: toward the viewer, the bottom of the top view, as in the SVG drawing.
  const GroundRegion region(k.polygon, k.holes);
  EXPECT_TRUE(polygon_contains(region, {11.2, -0.2}));
  EXPECT_FALSE(polygon_contains(region, {11.2, -1.8}));
  // Defaults: scale 1, offset 0.
  const Scene d = parse_scene(flock_scene(std::string(R"("svg_path": {"d": ")") + kL + R"("})"), "d.json");
  EXPECT_EQ(shape_of(d).polygon[3], Vec2(3, 3));
}

TEST(ShapeSvg, TheLargestSubpathIsTheOutlineAndTheOthersHoles) {
  // The hole's subpath comes first, and runs the same way round as the outline: even-odd, not winding.
  const Scene s = parse_scene(
      flock_scene(R"("svg_path": {"d": "M 2 2 h 2 v 2 h -2 z M 0 0 H 10 V 10 H 0 Z M 6 5 a 2 2 0 0 0 2 2 a 2 2 0 0 0 -2 -2 z"},
                     "holes": [{"circle": {"center": [2, 8], "radius": 1}}])"),
      "h.json");
  const ShapeKeyframe& k = shape_of(s);
  EXPECT_EQ(k.polygon.size(), 4u);
  ASSERT_EQ(k.holes.size(), 3u);  // two from the path, then the one given under "holes"
  const GroundRegion region(k.polygon, k.holes);
  EXPECT_FALSE(polygon_contains(region, {3, 3}));  // the square hole
  EXPECT_FALSE(polygon_contains(region, {7, 6}));  // the round hole (a circle through (6, 5) and (8, 7))
  EXPECT_FALSE(polygon_contains(region, {2, 8}));  // the hole given under "holes"
  EXPECT_TRUE(polygon_contains(region, {5, 5}));
  EXPECT_FALSE(polygon_contains(region, {11, 5}));
}

class ShapeSvgFile : public reliability::TempDirTest {};

TEST_F(ShapeSvgFile, ReadsEveryPathOfAnSvgFileBesideTheScene) {
  reliability::write_text(dir_ / "shape.svg", R"(<svg xmlns="http://www.w3.org/2000/svg">
  <path d="M 0 0 H 10 V 10 H 0 Z"/>
  <path d="M 3 3 H 7 V 7 H 3 Z"/>
</svg>
)");
  const Scene s = parse_scene(flock_scene(R"("svg_path": {"file": "shape.svg", "scale": 0.2})"), dir_ / "f.json");
  const ShapeKeyframe& k = shape_of(s);
  ASSERT_EQ(k.polygon.size(), 4u);
  ASSERT_EQ(k.holes.size(), 1u);
  EXPECT_EQ(k.polygon[2], Vec2(2, 2));
  EXPECT_LT((k.holes[0][0] - Vec2(0.6, 0.6)).norm(), 1e-12);

  reliability::write_text(dir_ / "bad.svg", "<svg>\n<path d=\"M 0 0 H 10 V 10 H 0 Z\"/>\n<path d=\"M 1 1 L 2 x\"/>\n</svg>");
  EXPECT_EQ(message(flock_scene(R"("svg_path": {"file": "bad.svg"})"), dir_ / "b.json"),
            (dir_ / "b.json").string() + ": /objectives/0/svg_path/file: " + (dir_ / "bad.svg").string() +
                ": <path> 1 at line 3: d: character 11 ('x'): expected a number for L (x y)");
  EXPECT_EQ(message(flock_scene(R"("svg_path": {"file": "none.svg"})"), dir_ / "b.json"),
            (dir_ / "b.json").string() + ": /objectives/0/svg_path/file: cannot open the SVG file " +
                (dir_ / "none.svg").string());
  reliability::write_text(dir_ / "moved.svg", "<svg>\n<path transform=\"translate(1)\" d=\"M 0 0 H 1 V 1 Z\"/></svg>");
  EXPECT_NE(message(flock_scene(R"("svg_path": {"file": "moved.svg"})"), dir_ / "b.json")
                .find("moved.svg: line 2: <path> has a \"transform\" attribute, which is not applied"),
            std::string::npos);
}

TEST(ShapeSvg, BadPathsNameTheFilePointerAndCharacter) {
  EXPECT_EQ(message(flock_scene(R"("svg_path": {"d": "M 0 0 L 1 x"})")),
            "bad.json: /objectives/0/svg_path/d: character 11 ('x'): expected a number for L (x y)");
  EXPECT_EQ(message(flock_scene(R"("svg_path": {"d": "M 0 0 H 4 V 4 H 0 Z M 3 3 H 6 V 6 H 3 Z"})")),
            "bad.json: /objectives/0/svg_path/d: the subpaths are one outline, the largest (subpath 0 at character "
            "1), and holes inside it that do not overlap: subpath 1 at character 21 has a point outside the outer shape");
  EXPECT_EQ(message(flock_scene(R"("svg_path": {"d": "M 0 0 H 9 V 9 H 0 Z M 1 1 H 5 V 5 H 1 Z M 4 4 H 6 V 6 H 4 Z"})")),
            "bad.json: /objectives/0/svg_path/d: the subpaths are one outline, the largest (subpath 0 at character "
            "1), and holes inside it that do not overlap: subpath 2 at character 41 overlaps subpath 1 at character 21");
  EXPECT_EQ(message(flock_scene(R"("svg_path": {"scale": 2})")),
            "bad.json: /objectives/0/svg_path: expected one of \"d\" (SVG path data, \"M 0 0 L 4 0 L 4 3 Z\") or "
            "\"file\" (an SVG file)");
  EXPECT_NE(message(flock_scene(R"("svg_path": {"d": "M 0 0 H 1 V 1 Z", "offset": [1, 2, 3]})"))
                .find("/objectives/0/svg_path/offset: expected [x, z]"),
            std::string::npos);
  EXPECT_NE(message(flock_scene(R"("svg_path": {"d": "M 0 0 H 1 V 1 Z", "scale": 0})")).find("/objectives/0/svg_path/scale"),
            std::string::npos);
  EXPECT_NE(message(flock_scene(R"("svg_path": {"d": "M 0 0 H 1 V 1 Z", "size": 1})"))
                .find("/objectives/0/svg_path/size: unknown key"),
            std::string::npos);
  EXPECT_NE(message(flock_scene(R"("svg_path": {"d": "M 0 0 H 1 V 1 Z"}, "polygon": [[0, 0], [1, 0], [0, 1]])"))
                .find("/objectives/0: expected one of \"polygon\""),
            std::string::npos);
  // The tolerance is in metres on the ground: a 1 km half circle at 1 µm needs more points than a shape may have.
  EXPECT_NE(message(flock_scene(R"("svg_path": {"d": "M 0 0 A 1 1 0 0 1 2 0 Z", "scale": 1000, "tolerance": 1e-6})"))
                .find("/objectives/0/svg_path/d: character 7 ('A'): the path flattens to more than"),
            std::string::npos);
}

TEST(ShapeSvg, FigureMeasuresCountAgentsInTheHolesAsOutside) {
  // A 6 x 4 rectangle with a round hole of radius 1 about (2, 2) and a square hole, 0.5 m per unit.
  const Scene scene = parse_scene(
      flock_scene(R"("svg_path": {"d": "M 0 0 H 12 V 8 H 0 Z M 2 4 A 2 2 0 0 1 6 4 A 2 2 0 0 1 2 4 Z m 6 -1 h 2 v 2 h -2 z",
                                  "scale": 0.5, "offset": [-3, -2]})",
                  8),
      "measured.json");
  // Ground: the rectangle [-3, 3] x [-2, 2], the round hole about (-1, 0), the square [1, 2] x [-0.5, 0.5].
  const std::vector<Vec2> at = {{-1, 0}, {-1.5, 0.3}, {1.5, 0}, {0.5, 0}, {2.5, 1.5}, {-2.5, -1.5}, {4, 0}, {0, -3}};
  VecX x = VecX::Zero(3 * at.size());
  for (size_t i = 0; i < at.size(); ++i) x[3 * i] = at[i].x(), x[3 * i + 2] = at[i].y();
  Trajectory t;
  t.particles = int(at.size());
  t.x.assign(11, x);
  t.v.assign(11, VecX::Zero(x.size()));
  const auto m = figure_measures(scene, t);
  ASSERT_TRUE(m.is_array() && !m.empty()) << m.dump();
  EXPECT_DOUBLE_EQ(m[0]["inside_fraction"].get<double>(), 3.0 / 8.0) << m.dump();
}

}  // namespace
}  // namespace kf
