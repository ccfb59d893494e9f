// The box and rectangle colliders through the real binary: a sheet dropped on a table (a rounded box) and
// on a panel (a rectangle) rests on them without passing through, report.json says so, export writes
// them; and a bad box or rectangle is refused in one line naming the file and the key's JSON pointer.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "../support/cli_test.h"

namespace kf {
namespace {
using namespace cli_test;

class BoxColliderCli : public TempDirTest {};

// A 0.6 m sheet, 10 x 10, held flat 5 cm above a table top at y = 0.75 (a box 1.0 x 0.75 x 0.6, rounded
// 2 cm) that is narrower than the sheet along z, so its two edges fall over the table's rounded edges.
std::string table_scene(const std::string& collider) {
  return R"({"seed": 1, "time": {"fps": 30, "frames": 20},
  "cloth": {"nx": 10, "ny": 10, "width": 0.6, "height": 0.6, "origin": [-0.3, 0.8, -0.3], "v_axis": [0, 0, 1],
            "colliders": [)" + collider + R"(]},
  "objectives": [{"type": "center_of_mass", "frame": 20, "target": [0, 0.75, 0]}]})";
}

const char* kBox = R"({"type": "box", "center": [0, 0.375, 0], "size": [1.0, 0.75, 0.4], "radius": 0.02,
                       "friction": 0.4})";
// A panel is no thicker than its contact: a sheet landing at 1 m/s needs a thicker contact than the
// default's 1 cm per 1/30 s step, or it passes through.
const char* kPanel = R"({"type": "rectangle", "center": [0, 0.75, 0], "width": 1.0, "height": 0.4,
                         "thickness": 0.04, "friction": 0.4})";

// The sheet lands and stays on the surface: no particle ever deeper than the contact thickness inside, the
// sheet resting on it at the end.
void expect_resting(const fs::path& run, const char* type, double thickness) {
  const Json report = Json::parse(read_text(run / "report.json"));
  const Json* m = nullptr;
  for (const Json& e : report["measures"])
    if (e.value("collider", -1) == 0) m = &e;
  ASSERT_NE(m, nullptr) << report.dump();
  EXPECT_EQ((*m)["type"], type);
  const double deepest = (*m)["min_distance"].get<double>();
  EXPECT_GT(deepest, -0.01) << "passed into the " << type;
  EXPECT_LT(deepest, thickness) << "never reached the " << type;
  EXPECT_GE((*m)["touching_at_end"].get<int>(), 30) << report.dump();
}

TEST_F(BoxColliderCli, ASheetRestsOnATableAndOnAPanelAndExportCarriesThem) {
  write("table.json", table_scene(kBox));
  write("panel.json", table_scene(kPanel));
  for (const char* name : {"table", "panel"}) {
    const auto r = run_keyframe(std::string("simulate ") + name + ".json --out " + name, dir_);
    ASSERT_EQ(r.code, 0) << r.output;
  }
  expect_resting(dir_ / "table", "box", 0.01);
  expect_resting(dir_ / "panel", "rectangle", 0.04);
  // The default 1 cm contact lets the falling sheet through the panel (scenes/README.md says so).
  write("thin.json", table_scene(R"({"type": "rectangle", "center": [0, 0.75, 0], "width": 1.0, "height": 0.4})"));
  ASSERT_EQ(run_keyframe("simulate thin.json --out thin", dir_).code, 0);
  const Json thin = Json::parse(read_text(dir_ / "thin/report.json"));
  EXPECT_EQ(thin["measures"].back()["touching_at_end"].get<int>(), 0) << thin.dump();
  const auto e = run_keyframe("export table --format obj", dir_);
  ASSERT_EQ(e.code, 0) << e.output;
  const std::string obj = read_text(dir_ / "table/export/frame_0010.obj");
  EXPECT_NE(obj.find("collider_0_box"), std::string::npos);
  const auto inspect = run_keyframe("inspect table.json", dir_);
  ASSERT_EQ(inspect.code, 0) << inspect.output;
  EXPECT_NE(inspect.output.find("box"), std::string::npos) << inspect.output;
}

struct BadCase {
  const char* collider;
  const char* pointer;
  const char* expected;
};

TEST_F(BoxColliderCli, ABadBoxOrRectangleIsRefusedInOneLineNamingItsKey) {
  const BadCase cases[] = {
      {R"({"type": "box", "size": [1, 0.1, 1], "radius": 0.08})", "/cloth/colliders/0/radius",
       "at most half the smallest"},
      {R"({"type": "box", "u_axis": [1, 0, 0], "v_axis": [1, 1, 0]})", "/cloth/colliders/0/v_axis", "perpendicular"},
      {R"({"type": "box", "size": [1, 0, 1]})", "/cloth/colliders/0/size", ""},
      {R"({"type": "rectangle", "width": -1})", "/cloth/colliders/0/width", ""},
      {R"({"type": "rectangle", "u_axis": [0, 0, 0]})", "/cloth/colliders/0/u_axis", "non-zero"},
      {R"({"type": "rectangle", "radius": 0.1})", "/cloth/colliders/0/radius", ""},
  };
  for (const BadCase& c : cases) {
    write("bad.json", table_scene(c.collider));
    const auto r = run_keyframe("simulate bad.json --out bad", dir_);
    EXPECT_EQ(r.code, kExitInput) << c.collider << "\n" << r.output;
    EXPECT_NE(r.output.find("bad.json"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(c.pointer), std::string::npos) << c.pointer << "\n" << r.output;
    EXPECT_NE(r.output.find(c.expected), std::string::npos) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_FALSE(fs::exists(dir_ / "bad")) << "partial output";
  }
}

}  // namespace
}  // namespace kf
