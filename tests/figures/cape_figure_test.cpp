// The cape blend (paper figure 6) in reduced form: two uncontrolled clips of a cape on the character are
// simulated and saved as runs, then the blend starts in clip A's state and is optimised to end in clip B's,
// judged by cape_end_state and run_stats as `keyframe optimize` reports them for scenes/cape-blend.json.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "adjoint/rollout.h"
#include "app/optimize_job.h"
#include "core/trajectory.h"
#include "report/cape_end_state.h"
#include "report/figure_measures.h"
#include "opt/optimizer.h"
#include "opt/problem.h"
#include "scene/scene.h"
#include "sim/make_system.h"
#include "../sim/character_test_util.h"

namespace kf {
namespace {

std::string cape_block(const std::string& time_keys) {
  return R"("cloth": {"nx": 6, "ny": 8, "width": 0.43, "height": 0.5, "origin": [-0.215, -0.03, -0.24],
              "mass": 0.1, "pins": "top_edge", "stretch": 300, "shear": 30, "bend": 1, "damping": 0.02,
              "air_drag": 0.2, "cg_tolerance": 1e-9},
    "character": {"file": ")" + test::character_asset().string() + R"(", "time": )" + time_keys + R"(,
                  "body": {"thickness": 0.015, "stiffness": 1000, "search": 0.06},
                  "self": {"thickness": 0.01, "stiffness": 200})";
}

// Frames of the uncontrolled simulation of a scene.
Trajectory frames_of_scene(const Scene& scene, Rollout& r) {
  auto sys = make_system(scene);
  VecX x0, v0;
  sys->initial_state(x0, v0);
  EXPECT_TRUE(simulate(*sys, x0, v0, std::vector<VecX>(scene.time.steps(), VecX::Zero(sys->dof())), r));
  Trajectory t;
  t.particles = sys->particles();
  t.fps = scene.time.fps;
  for (int f = 0; f <= scene.time.frames; ++f) {
    t.x.push_back(r.x[f * scene.time.substeps]);
    t.v.push_back(r.v[f * scene.time.substeps]);
  }
  return t;
}

TEST(CapeFigure, BlendEndsFarCloserToClipBThanTheUncontrolledCape) {
  test::TempDir dir;
  // Clip A settles, then starts the jump; clip B settles and goes on into the jump.
  for (const auto& [name, keys, frames] :
       {std::tuple{"a", "[[0, 0], [12, 0], [16, 0.2]]", 16}, std::tuple{"b", "[[0, 0], [12, 0], [24, 0.8]]", 24}}) {
    const Scene clip = parse_scene(R"({"time": {"fps": 30, "substeps": 2, "frames": )" + std::to_string(frames) +
                                       "}, " + cape_block(keys) + "}}",
                                   "clip.json");
    Rollout r;
    std::filesystem::create_directories(dir.path() / name);
    save_trajectory(dir.path() / name / "trajectory.bin", frames_of_scene(clip, r));
  }
  // The blend: from A's frame 16 to B's frame 24 in 8 frames (h = 1/120 s), while the body goes from 0.2 s to 0.8 s.
  std::string blend = R"({"time": {"fps": 30, "substeps": 4, "frames": 8}, )" + cape_block("[[0, 0.2], [8, 0.8]]");
  blend += R"(, "start": {"run": ")" + (dir.path() / "a").string() + R"(", "frame": 16},
      "end_target": {"run": ")" + (dir.path() / "b").string() + R"(", "frame": 24, "velocity_weight": 0.001}},
    "controls": {"kind": "per_frame", "alpha": 1e-6},
    "optimizer": {"max_evaluations": 80, "ftol_rel": 1e-12}})";
  const Scene scene = parse_scene(blend, "blend.json");
  auto sys = make_system(scene);
  Problem problem(scene, scene.time, *sys);
  const VecX z0 = problem.initial_guess();
  Rollout scratch;
  const Trajectory uncontrolled = frames_of_scene(scene, scratch);
  const OptimizeResult res = minimize(problem, scene.optimizer, z0);
  problem.evaluate(res.z, nullptr);
  ASSERT_FALSE(problem.last_diverged());
  Trajectory run;
  run.particles = sys->particles();
  for (int f = 0; f <= scene.time.frames; ++f) {
    run.x.push_back(problem.rollout().x[f * scene.time.substeps]);
    run.v.push_back(problem.rollout().v[f * scene.time.substeps]);
  }
  const nlohmann::json m = cape_end_state(scene, run, uncontrolled);
  std::printf("%s after %d evaluations (%s)\n", m.dump().c_str(), res.evaluations, res.status.c_str());
  const double before = m["uncontrolled"]["rms_position_error"], after = m["controlled"]["rms_position_error"];
  EXPECT_GT(before, 0.005) << "the clips end too close together for the check to mean anything";
  // Within 80 evaluations the exact adjoint gets to 0.59 of the uncontrolled error and the swap adjoint
  // to 0.64; both stay there to 200 (the effort and velocity terms hold the blend's optimum).
  EXPECT_LT(after, 0.7 * before);
  EXPECT_LT(m["controlled"]["rms_position_error_percent"].get<double>(), 2.0);
  EXPECT_GT(sys->run_stats()[0].second, 0) << "the cape never touched the body";
}

// scenes/cape-a.json (a stunt double dropped from a 1.5 m ledge) and scenes/cape-b.json (a calm take) as
// they are, then tests/figures/cape-blend-small.json -- scenes/cape-blend.json with 80 evaluations instead
// of 900, both written by scripts/make_cape_scenes.py -- through `keyframe optimize`'s own job.
// The stunt fall is chaotic, so where the blend starts, and how far 80 evaluations get from there, moves with
// any change to the solver's rounding. Scaling the clips' and blend's cg_tolerance by 0.7 to 1.4 (8 runs)
// gave uncontrolled errors of 3.8 to 5.1 % and controlled ones of 0.28 to 1.20 % (at most 0.24 of the
// uncontrolled), velocity errors at most 0.63 of the uncontrolled; 160 evaluations left the worst run where
// it was. So the bars here are what the reduced run meets on every one of those rounding variants; the
// figure's own bars (0.5 %, a quarter of the velocity error) are met by the full run, whose report is
// tests/results/runs/cape-blend/report.json (0.17 %). Without optimisation (max_evaluations 0) the position
// and velocity checks fail.
TEST(CapeFigure, BlendFromTheStuntFallEndsNearTheCalmTakesPositionsAndVelocities) {
  test::TempDir dir;
  const std::filesystem::path source(KEYFRAME_SOURCE_DIR);
  // A copy of a scene in the test's directory, its character file made absolute (runs it names resolve there).
  auto copy = [&](const std::filesystem::path& from, const std::string& name) {
    std::ifstream in(source / from);
    nlohmann::json j = nlohmann::json::parse(in);
    j["character"]["file"] = test::character_asset().string();
    const auto path = dir.path() / (name + ".json");
    std::ofstream(path) << j.dump(1);
    return path.string();
  };
  OptimizeOptions opt;
  opt.quiet = true;
  for (const char* clip : {"cape-a", "cape-b"}) {
    opt.out = (dir.path() / clip).string();
    optimize_job(copy(std::string("scenes/") + clip + ".json", clip), opt);
  }
  opt.out = (dir.path() / "blend").string();
  optimize_job(copy("tests/figures/cape-blend-small.json", "cape-blend"), opt);
  std::ifstream in(dir.path() / "blend" / "report.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  const nlohmann::json& end = report.at("cape_end_state");
  const nlohmann::json& stats = report.at("run_stats");
  std::printf("%s %s\n", end.dump().c_str(), stats.dump().c_str());
  const double before = end.at("uncontrolled").at("rms_position_error_percent");
  const double after = end.at("controlled").at("rms_position_error_percent");
  const double v_before = end.at("uncontrolled").at("rms_velocity_error");
  const double v_after = end.at("controlled").at("rms_velocity_error");
  EXPECT_GT(before, 3.0) << "the blend starts too close to clip B's end for the check to mean anything";
  EXPECT_LE(after, 0.3 * before);  // % of the cape's length
  EXPECT_LE(v_after, 0.75 * v_before);
  EXPECT_GE(stats.at("self_contacts").get<double>(), 100.0);
  EXPECT_GE(stats.at("body_contacts").get<double>(), 1000.0);
}

}  // namespace
}  // namespace kf
