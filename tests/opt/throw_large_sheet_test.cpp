// Large thrown sheets (opt/windows.cpp's thrown plan, opt/throw_search.h): the plan spends fewer
// evaluations when a flight is dear, a large sheet thrown through its keyframes still reaches them, and a job
// stopped during its throw search still writes its report.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/optimize_job.h"
#include "bench/job_deadline.h"
#include "opt/problem.h"
#include "opt/throw_search.h"
#include "opt/windows.h"
#include "scene/scene.h"
#include "sim/make_system.h"
#include "../sim/character_test_util.h"

namespace kf {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;

// An n x n sheet 0.8 m wide thrown from 1 m up, over `frames` frames of one step each.
std::string sheet(int n, int frames) {
  return R"("time": {"fps": 30, "substeps": 1, "frames": )" + std::to_string(frames) + R"(}, "cloth": {"nx": )" +
         std::to_string(n) + R"(, "ny": )" + std::to_string(n) +
         R"(, "width": 0.8, "height": 0.8, "origin": [-0.4, 1.0, -0.4], "u_axis": [1, 0, 0], "v_axis": [0, 0, 1],
         "velocity": [1, 2, 0], "mass": 0.3)";
}

Scene thrown_scene(int n, int frames, const std::string& optimizer = "{}") {
  return parse_scene("{" + sheet(n, frames) + R"(}, "controls": {"kind": "initial_velocity"},
      "objectives": [{"type": "center_of_mass", "frame": )" + std::to_string(frames) +
                         R"(, "target": [0.6, 1.2, 0.1]}], "optimizer": )" + optimizer + "}",
                     "thrown.json");
}

int planned(const StagePlan& plan) {
  int sum = 0;
  for (const StageSpec& s : plan.stages) sum += s.max_evaluations;
  return sum;
}

TEST(ThrowLargeSheet, ThePlanSpendsFewerEvaluationsWhenAFlightIsDear) {
  // A 12 x 12 sheet over 30 steps (4320 particle-steps): the whole budget, as before.
  const StagePlan small = plan_stages(thrown_scene(12, 30));
  EXPECT_EQ(planned(small), 300);
  EXPECT_EQ(small.scaled_budget, 0);
  EXPECT_EQ(small.stages[0].max_evaluations, 40);
  EXPECT_EQ(small.stages[1].max_evaluations, 60);
  // A 26 x 26 sheet over 30 steps (20280): 300 × (12000 / 20280)^1.5 = 136.5 of them, the rigid stage still 40.
  EXPECT_DOUBLE_EQ(large_flight_share(676, 30), 12000.0 / 20280.0);
  const StagePlan large = plan_stages(thrown_scene(26, 30));
  ASSERT_EQ(large.stages.size(), 3u);
  EXPECT_EQ(planned(large), 137);
  EXPECT_EQ(large.scaled_budget, 137);  // what a budget stop names
  EXPECT_EQ(large.stages[0].max_evaluations, 40);
  EXPECT_EQ(large.stages[1].max_evaluations, 32);
  EXPECT_EQ(large.stages[2].max_evaluations, 65);
  EXPECT_NE(large.why.find("137 of the 300 evaluations"), std::string::npos) << large.why;
  // Never below three stages' 12 evaluations each: a 50 x 50 sheet over 60 steps (the ring toss's size) keeps
  // 36 of 120, where the share alone would leave 3.
  EXPECT_EQ(planned(plan_stages(thrown_scene(50, 60, R"({"max_evaluations": 120})"))), 36);
  // A user's small budget is kept whole, never raised; two evaluations still plan a rigid and a per-particle stage.
  EXPECT_EQ(planned(plan_stages(thrown_scene(26, 30, R"({"max_evaluations": 2})"))), 2);
  EXPECT_EQ(planned(plan_stages(thrown_scene(26, 30, R"({"max_evaluations": 4})"))), 4);
}

// Position keyframes on three particles at the last frame, where the rigid throw z carries an n x n sheet.
std::string keyframes_of(int n, int frames, const VecX& z) {
  const Scene thrower = parse_scene("{" + sheet(n, frames) + R"(}, "controls": {"kind": "initial_rigid_velocity"},
      "objectives": [{"type": "center_of_mass", "frame": 1, "target": [0, 1, 0]}]})", "thrower.json");
  auto sys = make_system(thrower);
  Problem fly(thrower, thrower.time, *sys);
  fly.evaluate(z, nullptr);
  const VecX& x = fly.rollout().x[size_t(frames)];
  const int ids[3] = {0, n * n / 2 + n / 3, n * n - 1};
  std::ostringstream os;
  os.precision(17);
  os << R"("objectives": [{"type": "position", "frame": )" << frames << R"(, "particles": [)" << ids[0] << ","
     << ids[1] << "," << ids[2] << R"(], "targets": [)";
  for (int k = 0; k < 3; ++k)
    os << (k ? "," : "") << "[" << x[3 * ids[k]] << "," << x[3 * ids[k] + 1] << "," << x[3 * ids[k] + 2] << "]";
  os << "]}]";
  return os.str();
}

json report_of(const fs::path& dir) {
  std::ifstream in(dir / "report.json");
  return json::parse(in);
}

// A reduced large sheet: 24 x 24 over 25 frames (14400 particle-steps, a plan of 228 evaluations), thrown
// with a spin its scene does not have, reaches its three keyframes.
TEST(ThrowLargeSheet, AReducedLargeSheetThrownWithASpinReachesItsKeyframes) {
  test::TempDir dir;
  VecX z(6);
  z << 0.6, -0.4, 0.5, 1.5, -0.8, 2.0;  // m/s and rad/s
  std::ofstream(dir.path() / "large.json")
      << "{" << sheet(24, 25) << R"(}, "controls": {"kind": "initial_velocity"}, )" << keyframes_of(24, 25, z) << "}";
  OptimizeOptions opt;
  opt.out = (dir.path() / "run").string();
  opt.quiet = true;
  const OptimizeOutcome out = optimize_job(dir.path() / "large.json", opt);
  EXPECT_FALSE(out.failed) << out.diagnosis;
  EXPECT_FALSE(out.interrupted);
  const json report = report_of(dir.path() / "run");
  EXPECT_TRUE(report.at("diagnosis").at("reached").get<bool>());
  for (const json& k : report.at("keyframe_errors")) EXPECT_LT(k.at("miss_after").get<double>(), 1.0) << k.dump();
  EXPECT_LE(report.at("evaluations").get<int>(), 228);
}

// A job stopped while it searches throws (a bench's CPU limit) writes report.json for the best throw it flew:
// no evaluation, interrupted, the search's throws and the keyframes' errors there.
TEST(ThrowLargeSheet, AJobStoppedDuringItsThrowSearchStillReports) {
  test::TempDir dir;
  // A centre of mass below the ground: no throw reaches it, so the fits stall and the search runs on.
  std::ofstream(dir.path() / "search.json") << "{" << sheet(12, 40)
      << R"(, "colliders": [{"type": "ground"}]}, "controls": {"kind": "initial_velocity"},
      "objectives": [{"type": "center_of_mass", "frame": 40, "target": [0.5, -0.5, 0.2]}],
      "optimizer": {"throw_search": 100000}})";
  OptimizeOptions opt;
  opt.out = (dir.path() / "run").string();
  opt.quiet = true;
  OptimizeOutcome out;
  bool fired = false;
  {
    JobDeadline deadline(1.0, 120.0);
    out = optimize_job(dir.path() / "search.json", opt);
    fired = deadline.fired();
  }
  ASSERT_TRUE(fired);
  EXPECT_TRUE(out.interrupted);
  ASSERT_TRUE(fs::exists(dir.path() / "run" / "report.json"));
  const json report = report_of(dir.path() / "run");
  EXPECT_TRUE(report.at("interrupted").get<bool>());
  EXPECT_EQ(report.at("evaluations").get<int>(), 0);
  EXPECT_GT(report.at("throw_search").at("throws").get<int>(), 0);
  EXPECT_LT(report.at("throw_search").at("throws").get<int>(), 100000);
  ASSERT_EQ(report.at("keyframe_errors").size(), 1u);
  const json& k = report.at("keyframe_errors")[0];
  EXPECT_LE(k.at("miss_after").get<double>(), k.at("miss_before").get<double>());
}

}  // namespace
}  // namespace kf
