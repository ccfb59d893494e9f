// keyframe inspect: what a character file holds (the names and numbers a scene's character block needs), and
// a cape on a second character written from that output and scenes/README.md alone.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/mesh_sequence.h"
#include "core/trajectory.h"
#include "../support/cli_test.h"

namespace kf {
namespace {
using namespace cli_test;

const fs::path kSource = KEYFRAME_SOURCE_DIR;
const fs::path kWuson = "/usr/share/assimp/models/X/Testwuson.X";  // Debian's assimp-testmodels (scripts/setup)

Json inspect_json(const fs::path& file) {
  const auto r = run_keyframe("inspect '" + file.string() + "' --json", kSource);
  EXPECT_EQ(r.code, 0) << r.output;
  return Json::parse(r.output);
}

std::vector<std::string> names_of(const Json& list, bool bones_only = false) {
  std::vector<std::string> out;
  for (const Json& e : list)
    if (!bones_only || e["bone"].get<bool>()) out.push_back(e["name"]);
  return out;
}

bool contains(const std::vector<std::string>& v, const std::string& s) { return std::find(v.begin(), v.end(), s) != v.end(); }

class InspectCli : public TempDirTest {};

TEST_F(InspectCli, ListsTheShippedCharactersMeshesBonesAndAnimation) {
  const Json j = inspect_json(kSource / "assets/character/BCN_Epileptic.X");
  EXPECT_EQ(names_of(j["meshes"]), (std::vector<std::string>{"Torso", "Head", "Legs"}));
  int vertices = 0, triangles = 0;
  for (const Json& m : j["meshes"]) vertices += m["vertices"].get<int>(), triangles += m["triangles"].get<int>();
  EXPECT_EQ(vertices, 3014);  // what the character loads (tests/sim/character_load_test.cpp)
  EXPECT_EQ(triangles, 5126);
  const auto bones = names_of(j["nodes"], true);
  EXPECT_EQ(bones.size(), 54u);
  EXPECT_TRUE(contains(bones, "B_Clavicle_Left") && contains(bones, "B_Neck")) << j["nodes"].dump();
  ASSERT_EQ(j["animations"].size(), 1u);
  EXPECT_DOUBLE_EQ(j["animations"][0]["seconds"].get<double>(), 3.3);
  EXPECT_DOUBLE_EQ(j["animations"][0]["ticks"].get<double>(), 15840);
  EXPECT_DOUBLE_EQ(j["animations"][0]["ticks_per_second"].get<double>(), 4800);
  // 1.814 m tall, Y up.
  EXPECT_NEAR(j["bounds"]["size"][1].get<double>(), 1.814, 0.001);

  // The text a user reads says the same.
  const auto text = run_keyframe("inspect assets/character/BCN_Epileptic.X", kSource);
  ASSERT_EQ(text.code, 0) << text.output;
  EXPECT_NE(text.output.find("meshes (3;"), std::string::npos) << text.output;
  EXPECT_NE(text.output.find("  0 "), std::string::npos) << text.output;
  EXPECT_NE(text.output.find(": 3.3 s (1.584e+04 ticks at 4800 a second)"), std::string::npos) << text.output;
  EXPECT_NE(text.output.find(", 54 bones;"), std::string::npos) << text.output;
  EXPECT_NE(text.output.find("B_Clavicle_Left [bone]"), std::string::npos) << text.output;
}

TEST_F(InspectCli, ListsTheSecondCharactersMeshesBonesAndAnimations) {
  ASSERT_TRUE(fs::exists(kWuson)) << kWuson << " missing: install Debian's assimp-testmodels (scripts/setup)";
  const Json j = inspect_json(kWuson);
  EXPECT_EQ(names_of(j["meshes"]).size(), 1u);
  const auto bones = names_of(j["nodes"], true);
  for (const char* b : {"Spine_Front04", "ForeLeg_L_01", "ForeLeg_R_01", "Neck", "Tail01"})
    EXPECT_TRUE(contains(bones, b)) << b << " not a bone in " << j["nodes"].dump();
  std::map<std::string, double> seconds;
  for (const Json& a : j["animations"]) seconds[a["name"]] = a["seconds"];
  ASSERT_EQ(seconds.size(), 3u) << j["animations"].dump();
  EXPECT_NEAR(seconds["Wuson_Run"], 4640.0 / 4800, 1e-12);
  EXPECT_NEAR(seconds["Wuson_Walk"], 17280.0 / 4800, 1e-12);
  EXPECT_EQ(j["animations"][1]["name"], "Wuson_Walk");
}

// tests/app/wuson-cape.json was written from scenes/README.md (the character block) and the output of
// `keyframe inspect Testwuson.X`: three bones across the shoulders (bind-pose positions x = -0.30, 0, 0.30 at
// y ~ 1.06-1.10, z ~ 0.61-0.66), the walk (animation 1, 3.6 s: longer than the scene), no "time" block; the
// sheet laid flat over the back from the shoulders towards the tail. Its straight top edge starts up to
// 0.23 m from the anchors (keyframe warns): the anchors follow the skin vertices nearest the three bones,
// an arch over the shoulders at frame 0 that a straight edge cannot follow.
TEST_F(InspectCli, CapeOnTheSecondCharacterByBoneNamesAnimatesAndRuns) {
  ASSERT_TRUE(fs::exists(kWuson)) << kWuson << " missing: install Debian's assimp-testmodels (scripts/setup)";
  const fs::path scene = kSource / "tests/app/wuson-cape.json";
  const auto bones = names_of(inspect_json(kWuson)["nodes"], true);
  for (const char* b : {"ForeLeg_R_01", "Spine_Front04", "ForeLeg_L_01"}) EXPECT_TRUE(contains(bones, b)) << b;

  const auto sim = run_keyframe("simulate '" + scene.string() + "' --out sim", dir_);
  ASSERT_EQ(sim.code, 0) << sim.output;
  EXPECT_EQ(sim.output.find("/character/time"), std::string::npos) << sim.output;  // not frozen
  EXPECT_EQ(sim.output.find("ends at"), std::string::npos) << sim.output;          // the walk outlasts the scene
  const Trajectory t = load_trajectory(dir_ / "sim/trajectory.bin");
  ASSERT_EQ(t.particles, 9 * 12);
  ASSERT_EQ(t.frames(), 21);
  // The body walks from frame 0 on (without "time" the animation plays at its own rate):
  // its vertices move 0.3 m by frame 20, and the pinned top edge (row 11) follows its shoulders.
  const MeshSequence body = load_mesh_sequence(dir_ / "sim/meshes.bin");
  ASSERT_EQ(body.frames(), 21);
  const int v = body.meshes.at(0).vertices;
  double body_moved = 0, edge_moved = 0;
  const float* a = body.vertex_positions(0, 0);
  const float* b = body.vertex_positions(20, 0);
  for (int i = 0; i < 3 * v; i += 3) {
    body_moved = std::max(body_moved, double(Vec3(b[i] - a[i], b[i + 1] - a[i + 1], b[i + 2] - a[i + 2]).norm()));
  }
  for (int p = 0; p < t.particles; ++p) {
    for (int f = 0; f < t.frames(); ++f) ASSERT_TRUE(t.x[size_t(f)].segment(3 * p, 3).allFinite());
    if (p >= 99) edge_moved = std::max(edge_moved, (t.x[20].segment(3 * p, 3) - t.x[1].segment(3 * p, 3)).norm());
  }
  EXPECT_GT(body_moved, 0.2);
  EXPECT_GT(edge_moved, 0.005);

  // And it optimises (a short budget: the keyframe is not the point here, the run is).
  const auto opt = run_keyframe("optimize '" + scene.string() + "' --out opt", dir_);
  EXPECT_NE(opt.output.find("evaluation limit reached after"), std::string::npos) << opt.output;
  const Json report = Json::parse(read_text(dir_ / "opt/report.json"));
  EXPECT_TRUE(report.contains("measures")) << report.dump();
  EXPECT_TRUE(fs::exists(dir_ / "opt/controls.bin"));
}

TEST_F(InspectCli, SceneIsPrintedWithItsDefaultsFilledIn) {
  write("s.json", reliability::small_cloth_scene());
  const auto r = run_keyframe("inspect s.json", dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  const Json j = Json::parse(r.output);
  EXPECT_EQ(j["cloth"]["nx"], 5);                // stated
  EXPECT_EQ(j["cloth"]["stretch"], 500.0);       // default
  EXPECT_EQ(j["time"]["substeps"], 1);           // default
  EXPECT_EQ(j["optimizer"]["max_evaluations"], 6);
  EXPECT_EQ(j["objectives"][0]["weight"], 1.0);  // default inside a list
}

TEST_F(InspectCli, UnreadableFileIsOneLineNamingIt) {
  write("broken.X", "xof 0303txt 0032\nFrame {");
  for (const char* f : {"missing.X", "broken.X"}) {
    const auto r = run_keyframe(std::string("inspect ") + f, dir_);
    EXPECT_NE(r.code, 0);
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_NE(r.output.find(std::string("keyframe: error: ") + f + ": "), std::string::npos) << r.output;
  }
}

}  // namespace
}  // namespace kf
