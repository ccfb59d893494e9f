// Reduced versions of robustness-suite scenes (scenes/robustness/), read from the suite's own files and made
// smaller, optimised through `keyframe optimize`'s job at their default settings and judged by the suite's
// criterion (every keyframe within its tolerance: opt/diagnosis.h). The full suite is
// `keyframe bench --only robustness`.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "app/optimize_job.h"
#include "../reliability/cli_harness.h"
#include "../sim/character_test_util.h"

namespace kf {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

json suite_scene(const std::string& name) {
  std::ifstream in(fs::path(KEYFRAME_SOURCE_DIR) / "scenes" / "robustness" / (name + ".json"));
  return json::parse(in);
}

// Writes `scene` into dir, optimises it and returns its report.
json optimise(const json& scene, const fs::path& dir) {
  std::ofstream(dir / "scene.json") << scene.dump(1);
  OptimizeOptions opt;
  opt.quiet = true;
  opt.out = (dir / "run").string();
  const OptimizeOutcome outcome = optimize_job(dir / "scene.json", opt);
  EXPECT_FALSE(outcome.failed) << outcome.diagnosis;
  std::ifstream in(dir / "run" / "report.json");
  return json::parse(in);
}

// The same through the binary, for scenes with a character: building its body's ray-tracing hierarchy in the
// library trips the tests' floating-point traps.
json optimise_with_the_binary(const json& scene, const fs::path& dir) {
  std::ofstream(dir / "scene.json") << scene.dump(1);
  const auto r = reliability::run_keyframe("optimize scene.json --out run", dir);
  EXPECT_EQ(r.code, 0) << r.output;
  std::ifstream in(dir / "run" / "report.json");
  return json::parse(in);
}

void expect_every_keyframe_met(const json& report) {
  EXPECT_EQ(report.at("diagnosis").at("outcome"), "reached") << report.at("diagnosis").dump();
  for (const json& k : report.at("keyframe_errors")) {
    EXPECT_TRUE(k.at("judged").get<bool>()) << k.dump();
    EXPECT_TRUE(k.at("met").get<bool>()) << k.dump();
    EXPECT_GT(k.at("miss_before").get<double>(), 1.0) << "met without optimising: " << k.dump();
  }
}

TEST(Robustness, SheetDroppedOnTheGroundSlidesToItsKeyframes) {
  json scene = suite_scene("drop-ground");  // centre of mass and a corner 20 cm along +x
  scene["cloth"]["nx"] = 8;
  scene["cloth"]["ny"] = 8;
  test::TempDir dir;
  expect_every_keyframe_met(optimise(scene, dir.path()));
}

// The scene with the stop rule off, so that every stage of its plan runs (the windows are what is tested).
json every_stage_of(json scene) {
  scene["optimizer"]["stop_when_reached"] = false;
  return scene;
}

// The towel dropped beside its thin rail, asked to hang centred on it (the suite's scene as it is): one
// force per particle over the whole horizon stalls 4 cm away on rough ground (NotReached.Towel...); the
// default's windows on the lattice of forces reach it. At default settings the first window may already
// reach it and stop there.
TEST(Robustness, TowelDroppedBesideItsRailHangsCentredOnItThroughLatticeWindows) {
  test::TempDir dir;
  expect_every_keyframe_met(optimise(suite_scene("towel-rail-offcentre"), dir.path()));
  const json report = optimise(every_stage_of(suite_scene("towel-rail-offcentre")), dir.path());
  expect_every_keyframe_met(report);
  ASSERT_GE(report.at("stage_results").size(), 2u);
  EXPECT_EQ(report.at("stage_results")[0].at("kind"), "per_frame_lattice");
  EXPECT_EQ(report.at("stage_results").back().at("kind"), "per_frame");
}

// The flag released in its vertical plane (the suite's scene as it is): with the default waviness its start
// is tame (the force gradient grows a few hundredfold, below optimizer.window_growth), so it runs as one
// stage, which ends early (seed 1 converges on forces costing 5e-2; seeds 2-5 stall at 7e-3 to 3e-2); the
// windows from no force that follow, with the evaluations left, end a hundred times lower.
TEST(Robustness, FlagWhoseOneStageEndsEarlyGoesOnInWindows) {
  test::TempDir dir;
  expect_every_keyframe_met(optimise(suite_scene("flag-released"), dir.path()));
  const json report = optimise(every_stage_of(suite_scene("flag-released")), dir.path());
  expect_every_keyframe_met(report);
  const json& stages = report.at("stage_results");
  ASSERT_GE(stages.size(), 3u) << stages.dump();
  EXPECT_EQ(stages[0].at("kind"), "per_frame");
  EXPECT_NE(stages[0].at("status").get<std::string>().rfind("evaluation limit", 0), 0u) << stages.dump();
  EXPECT_EQ(stages[1].at("kind"), "per_frame_lattice");
  EXPECT_EQ(stages.back().at("kind"), "per_frame");
  EXPECT_LT(stages.back().at("objective_end").get<double>(), 0.01 * stages[0].at("objective_end").get<double>());
  int evaluations = 0;
  for (const json& s : stages) evaluations += s.at("evaluations").get<int>();
  EXPECT_LE(evaluations, suite_scene("flag-released").value("optimizer", json::object()).value("max_evaluations", 300));
}

// A 1.4 m tablecloth dropped onto a table (a rounded box, friction 0.4), one corner to hang at a mark beside
// the table's corner (the suite's scene as it is, at four substeps a frame: at one, sliding contact on the
// box stalls the line search 2 cm away, tests/results/shots/README.md).
TEST(Robustness, TableclothOnATableHangsACornerAtItsMark) {
  test::TempDir dir;
  expect_every_keyframe_met(optimise(suite_scene("tablecloth-table"), dir.path()));
}

// An 11 x 11 napkin on the ground with self contact, its top edge keyframed onto its bottom edge 4 cm up and
// its bottom edge kept in place: folded in half at defaults (tests/results/shots/README.md), its layers apart.
TEST(Robustness, NapkinFoldsInHalfAtItsMark) {
  test::TempDir dir;
  const json report = optimise(suite_scene("napkin-fold"), dir.path());
  const json& keyframes = report.at("keyframe_errors");  // the top edge, then the bottom edge (met unaided)
  EXPECT_EQ(report.at("diagnosis").at("outcome"), "reached") << report.at("diagnosis").dump();
  ASSERT_EQ(keyframes.size(), 2u);
  EXPECT_GT(keyframes[0].at("miss_before").get<double>(), 1.0) << keyframes[0].dump();
  for (const json& k : keyframes) EXPECT_TRUE(k.at("met").get<bool>()) << k.dump();
  for (const json& m : report.at("measures"))
    if (m.at("type") == "ground") EXPECT_GT(m.at("lowest_at_end").get<double>(), 0.0) << m.dump();
}

// A cape hung by anchors on a Z-up Blender figure in its own units (BLEND/HUMAN.blend, scale 0.17, up_axis
// "z"), its hem's centre lifted and swung back from where it hangs unaided ("from": "uncontrolled"). Through
// the binary: building this figure's ray-tracing hierarchy in the library trips the tests' floating-point traps.
TEST(Robustness, CapeOnAZUpBlenderFigureLiftsItsHemFromWhereItHangs) {
  test::TempDir dir;
  std::ofstream(dir.path() / "scene.json") << suite_scene("cape-human-blend").dump(1);
  const auto r = reliability::run_keyframe("optimize scene.json --out run", dir.path());
  ASSERT_EQ(r.code, 0) << r.output;
  std::ifstream in(dir.path() / "run" / "report.json");
  const json report = json::parse(in);
  expect_every_keyframe_met(report);
  // Unaided, the hem misses by the offset itself: [0, 0.1, -0.2] m, 22.4 cm, in tolerances of 1 cm.
  EXPECT_NEAR(report.at("keyframe_errors")[0].at("miss_before").get<double>(), 100 * std::sqrt(0.05), 1e-4);
}

// A blanket hung from the shoulders of the Z-up SMD Wuson at half its size (scale 0.5, up_axis "z"; the
// anchors in metres after both): unaided it slides off the -x flank, far from the hem's mark on the rump
// (tests/results/shots/README.md).
TEST(Robustness, CapeOnAHalfScaleZUpSmdCreatureKeepsItsHemOnTheBack) {
  const json scene = suite_scene("cape-wuson-smd");
  ASSERT_EQ(scene.at("character").at("scale"), 0.5);
  ASSERT_EQ(scene.at("character").at("up_axis"), "z");
  test::TempDir dir;
  const json report = optimise_with_the_binary(scene, dir.path());
  expect_every_keyframe_met(report);
  EXPECT_GT(report.at("keyframe_errors")[0].at("miss_before").get<double>(), 30.0);
  // The controls do not press the cape into the body: no particle goes deeper than in the unaided run.
  EXPECT_GT(report.at("run_stats").at("min_body_distance").get<double>(),
            report.at("uncontrolled_run_stats").at("min_body_distance").get<double>() - 1e-3)
      << report.at("run_stats").dump();
}

// A free 12 x 12 sheet dropped onto the still Collada/human.zae (no anchors), its centre of mass asked to be
// over the right shoulder. Frictionless, unaided it slides off the shoulder and falls, and the optimiser
// stalls short of the mark; with friction 0.5 on the body (cloth on clothing) it stays on the shoulder, below
// the mark, and reaches it at defaults (tests/results/shots/README.md, "The drape, with friction on the body").
TEST(Robustness, SheetDroppedOnAStillFigureDrapesOverItsRightShoulder) {
  const json scene = suite_scene("drape-human");
  ASSERT_FALSE(scene.at("character").contains("anchors"));
  ASSERT_EQ(scene.at("character").at("body").at("friction"), 0.5);
  test::TempDir dir;
  const json report = optimise_with_the_binary(scene, dir.path());
  expect_every_keyframe_met(report);
  EXPECT_GT(report.at("keyframe_errors")[0].at("miss_before").get<double>(), 15.0);
}

TEST(Robustness, FortyAgentsFillASmallerTriangle) {
  json scene = suite_scene("flock-triangle");
  scene["flock"]["agents"] = 40;
  scene["flock"]["spawn"]["radius"] = 4;
  scene["objectives"][0]["polygon"] = json::parse("[[-4.5, 3], [4.5, 3], [0, 14]]");
  test::TempDir dir;
  expect_every_keyframe_met(optimise(scene, dir.path()));
}

}  // namespace
}  // namespace kf
