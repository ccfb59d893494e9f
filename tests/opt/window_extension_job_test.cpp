// A window still descending at its limit goes on (opt/window_extension.h), through `keyframe optimize`'s job on
// the generated suite's drop-collider-9 (a sheet dropped onto a sphere with friction, keyframes at frames 17 and
// 35), whose first window stops at its planned share still falling: it borrows from the stages after it, its
// best objective falls below what it had at its share, and the run spends no more than its budget. A run cut in
// the borrowed evaluations and resumed ends with the same controls as one never cut.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "app/optimize_job.h"
#include "core/error.h"
#include "opt/windows.h"
#include "scene/scene.h"
#include "../reliability/cli_harness.h"
#include "../sim/character_test_util.h"
#include "../support/interrupted_run.h"

namespace kf {
namespace {

using nlohmann::json;

const std::filesystem::path kScene = std::filesystem::path(KEYFRAME_SOURCE_DIR) / "tests/results/reachable/scenes/drop-collider-9.json";

// The best φ of stage 1 over its first `n` evaluations (iterations.csv: evaluation,seconds,phi,...,stage,...).
double best_of_first_stage(const std::filesystem::path& csv, int n) {
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  double best = std::numeric_limits<double>::infinity();
  int seen = 0;
  while (std::getline(in, line) && seen < n) {
    std::stringstream row(line);
    std::string evaluation, seconds, phi, grad, stage;
    std::getline(row, evaluation, ',');
    std::getline(row, seconds, ',');
    std::getline(row, phi, ',');
    std::getline(row, grad, ',');
    std::getline(row, stage, ',');
    if (stage != "1") break;
    best = std::min(best, std::stod(phi));
    ++seen;
  }
  return best;
}

TEST(WindowExtensionJob, AFirstWindowStillFallingAtItsShareBorrowsEndsLowerAndResumesAsIfNeverCut) {
  const Scene scene = load_scene(kScene);
  const StagePlan plan = plan_stages(scene);
  ASSERT_GT(plan.stages.size(), 2u);
  const int share = plan.stages.front().max_evaluations;
  test::TempDir dir;
  const int whole_code = test::run_keyframe_interrupted(dir.path(), {"optimize", kScene.string(), "--out", "run"});
  EXPECT_EQ(whole_code, kExitNotReached);
  std::ifstream in(dir.path() / "run" / "report.json");
  const json report = json::parse(in);
  const json& first = report.at("stage_results").at(0);
  const int first_evaluations = first.at("evaluations").get<int>();
  EXPECT_GT(first_evaluations, share) << "the first window did not go on";
  EXPECT_LE(report.at("evaluations").get<int>(), scene.optimizer.max_evaluations);
  const double at_share = best_of_first_stage(dir.path() / "run" / "iterations.csv", share);
  EXPECT_LT(first.at("objective_end").get<double>(), at_share);
  std::ifstream log_in(dir.path() / "run" / "log.txt");
  const std::string log((std::istreambuf_iterator<char>(log_in)), std::istreambuf_iterator<char>());
  EXPECT_NE(log.find("borrowed from the stages after it"), std::string::npos);
  std::printf("drop-collider-9: first window %d evaluations (share %d), objective %.4g (%.4g at its share)\n",
              first_evaluations, share, first.at("objective_end").get<double>(), at_share);

  // Cut half way through the first borrowed chunk, then resumed: the tape replays the evaluations and the rule
  // decides again from them.
  const int cut_after = share + share / 2;
  ASSERT_LT(cut_after, first_evaluations);
  EXPECT_EQ(test::run_keyframe_interrupted(dir.path(), {"optimize", kScene.string(), "--out", "cut"}, cut_after),
            kExitInterrupted);
  EXPECT_EQ(test::run_keyframe_interrupted(dir.path(), {"optimize", "--resume", "cut"}), whole_code);
  EXPECT_EQ(reliability::read_text(dir.path() / "cut" / "controls.bin"),
            reliability::read_text(dir.path() / "run" / "controls.bin"));
}

}  // namespace
}  // namespace kf
