// What a run prints says what it counts, through the real binary: the cloth summary names each collider
// (those the scene declared and those the system adds: a character's body, self contact) instead of a bare
// count; every run_stats key report.json holds is documented where report.json is (scenes/README.md);
// and a scene without controls.kind is optimised with the default the parser and ControlSpec share.
#include <gtest/gtest.h>

#include <string>
#include <utility>

#include "scene/scene.h"
#include "../support/cli_test.h"

namespace kf {
namespace {
using namespace cli_test;

class RunWordsCli : public TempDirTest {
 protected:
  void write(const std::string& name, const std::string& text) { reliability::write_text(dir_ / name, text); }
  // `keyframe simulate NAME.json`: its output, its report.json.
  std::string simulate(const std::string& name, Json* report = nullptr) {
    const auto r = run_keyframe("simulate " + name + ".json --out " + name, dir_);
    EXPECT_EQ(r.code, 0) << r.output;
    if (report) *report = Json::parse(read_text(dir_ / name / "report.json"));
    return r.output;
  }
};

const fs::path kHuman = "/usr/share/assimp/models/Collada/human.zae";  // Debian's assimp-testmodels

// A 5 x 5 sheet, 4 frames; `cloth` is pasted into its cloth block, `rest` after it.
std::string sheet(const std::string& cloth, const std::string& rest = "") {
  return R"({"seed": 1, "time": {"fps": 30, "frames": 4},
    "cloth": {"nx": 5, "ny": 5, "width": 0.4, "height": 0.4, "origin": [-0.52, 1.6, -0.15],
              "u_axis": [1, 0, 0], "v_axis": [0, 0, 1])" + cloth + "}" + rest + "}";
}

// The `cloth: ...` clause of simulate's first line.
std::string cloth_clause(const std::string& output) {
  const size_t at = output.find("cloth: ");
  return at == std::string::npos ? output : output.substr(at, output.find('\n', at) - at);
}

TEST_F(RunWordsCli, TheClothSummaryNamesEachColliderItCounts) {
  ASSERT_TRUE(fs::exists(kHuman)) << kHuman << " missing: install Debian's assimp-testmodels (scripts/setup)";
  write("bare.json", sheet(""));
  write("declared.json", sheet(R"(, "colliders": [{"type": "ground"}, {"type": "sphere", "center": [0, 0, 0],
                                   "radius": 0.3}], "self": {"enabled": true})"));
  // A sheet dropped on a figure: the scene declares no collider, the system adds the body (and self contact).
  write("drape.json", sheet("", R"(, "character": {"file": ")" + kHuman.string() + R"("})"));
  EXPECT_NE(cloth_clause(simulate("bare")).find(" 0 pinned, no colliders, "), std::string::npos)
      << cloth_clause(simulate("bare"));
  const std::string declared = cloth_clause(simulate("declared"));
  EXPECT_NE(declared.find(" 3 colliders (ground, sphere, self contact), "), std::string::npos) << declared;
  Json report;
  const std::string drape = simulate("drape", &report);
  const std::string clause = cloth_clause(drape);
  EXPECT_NE(clause.find(" 0 pinned, 2 colliders (body, self contact), "), std::string::npos) << clause;
  // report.json's "system" is the same words.
  EXPECT_NE(report["system"].get<std::string>().find(clause.substr(0, clause.find(", PCG"))), std::string::npos)
      << report["system"];
}

// Every key of report.json's run_stats, from a plain sheet, a sheet with colliders and a sheet on a body,
// is explained in scenes/README.md's run_stats list (`key`: ...).
TEST_F(RunWordsCli, EveryRunStatIsDocumentedWhereReportJsonIs) {
  ASSERT_TRUE(fs::exists(kHuman)) << kHuman;
  write("bare.json", sheet(""));
  write("ground.json", sheet(R"(, "colliders": [{"type": "ground"}])"));
  write("drape.json", sheet("", R"(, "character": {"file": ")" + kHuman.string() + R"("})"));
  const std::string docs = read_text(fs::path(KEYFRAME_SOURCE_DIR) / "scenes/README.md");
  const size_t section = docs.find("`run_stats`");
  ASSERT_NE(section, std::string::npos) << "scenes/README.md does not document run_stats";
  int keys = 0;
  for (const char* name : {"bare", "ground", "drape"}) {
    Json report;
    simulate(name, &report);
    ASSERT_TRUE(report.contains("run_stats")) << name << ": " << report.dump();
    for (const auto& [key, value] : report["run_stats"].items()) {
      ++keys;
      EXPECT_NE(docs.find("`" + key + "`", section), std::string::npos)
          << name << ": run_stats key \"" << key << "\" (" << value << ") is not in scenes/README.md";
    }
  }
  EXPECT_GE(keys, 8);  // split_steps and pcg_iterations_per_step each time, the body's contacts on the figure
}

// A scene file without controls.kind gets ControlSpec's own default, per_frame forces: the parser reads it
// from there, and optimize reports the kind it ran.
TEST_F(RunWordsCli, ASceneWithoutControlsKindIsOptimisedWithPerFrameForces) {
  EXPECT_EQ(ControlSpec{}.kind, ControlKind::kPerFrame);
  write("lift.json", R"({"seed": 1, "time": {"fps": 30, "substeps": 2, "frames": 4},
    "cloth": {"nx": 4, "ny": 4, "width": 0.3, "height": 0.3, "origin": [0, 1, 0], "pins": "top_edge"},
    "objectives": [{"type": "height", "frame": 4, "height": 1.0}],
    "optimizer": {"max_evaluations": 3}})");
  EXPECT_EQ(load_scene(dir_ / "lift.json").controls.kind, ControlSpec{}.kind);
  const auto r = run_keyframe("optimize lift.json --out lift --quiet", dir_);
  ASSERT_TRUE(r.code == 0 || r.code == 7) << r.output;
  const Json report = Json::parse(read_text(dir_ / "lift/report.json"));
  EXPECT_EQ(report["controls"], "per_frame") << report.dump();
  // per_frame: one force a frame per particle (4 frames, 16 particles), not one a step (8 steps).
  EXPECT_EQ(report["control_variables"], 4 * 16 * 3) << report.dump();
}

// A flock keyframe off the ground, through the binary: exit 3, one line naming the file, the JSON pointer
// and what was expected, and no run directory.
TEST_F(RunWordsCli, AFlockTargetOffTheGroundIsRefusedInOneLineWithNoRun) {
  write("f.json", R"({"time": {"frames": 10}, "flock": {"agents": 4},
    "objectives": [{"type": "center_of_mass", "frame": 5, "target": [1, 0.5, 2]}]})");
  for (const char* command : {"simulate", "optimize"}) {
    const auto r = run_keyframe(std::string(command) + " f.json --out run", dir_);
    EXPECT_EQ(r.code, 3) << command << ": " << r.output;
    EXPECT_EQ(r.output,
              "keyframe: error: f.json: /objectives/0/target: expected a point on the ground, y = 0 (a flock moves on "
              "the ground and cannot reach y = 0.5)\n")
        << command;
    EXPECT_FALSE(fs::exists(dir_ / "run")) << command;
  }
}

// A particle selector that matches nothing, in a keyframe and in the pins, or names a row the sheet does not
// have, through the binary: exit 3, one line naming the file, the key's JSON pointer and the sheet's ranges,
// and no run directory.
TEST_F(RunWordsCli, ASelectorThatMatchesNothingIsRefusedInOneLineWithNoRun) {
  auto scene = [](const std::string& selector, const std::string& pins) {
    return R"({"time": {"frames": 4}, "cloth": {"nx": 5, "ny": 5, "width": 0.4, "height": 0.4)" + pins +
           R"(}, "objectives": [{"type": "position", "frame": 2, "particles": )" + selector +
           R"(, "targets": [[0, 1, 0]]}]})";
  };
  write("region.json", scene(R"({"u": [0.5, 0.6]})", ""));
  write("pins.json", scene(R"({"row": 2})", R"(, "pins": {"i": [3, 4], "u": [0, 0.2]})"));
  write("row.json", scene(R"({"row": 7})", ""));
  const std::pair<const char*, const char*> cases[] = {
      {"region", "keyframe: error: region.json: /objectives/0/particles: selects no particle of the 5 x 5 sheet "
                 "({\"u\":[0.5,0.6]}; i runs 0 … 4, j 0 … 4, u 0 … 0.4 m, v 0 … 0.4 m)\n"},
      {"pins", "keyframe: error: pins.json: /cloth/pins: selects no particle of the 5 x 5 sheet "
               "({\"i\":[3,4],\"u\":[0,0.2]}; i runs 0 … 4, j 0 … 4, u 0 … 0.4 m, v 0 … 0.4 m)\n"},
      {"row", "keyframe: error: row.json: /objectives/0/particles/row: expected an integer in [0, 4], got 7\n"}};
  for (const auto& [name, message] : cases) {
    const auto r = run_keyframe(std::string("simulate ") + name + ".json --out run", dir_);
    EXPECT_EQ(r.code, 3) << r.output;
    EXPECT_EQ(r.output, message);
    EXPECT_FALSE(fs::exists(dir_ / "run")) << name;
  }
}

}  // namespace
}  // namespace kf
