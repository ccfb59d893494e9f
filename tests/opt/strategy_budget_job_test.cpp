// The budget is the user's: a scene whose optimizer.max_evaluations is below what the strategy would plan
// gets fewer windows (opt/windows.h), and ends at least as close to its keyframes as the same scene run at
// the full budget and cut at that many evaluations. Both through the real binary, on reduced generated
// scenes (bench/bench_reachable.h): a sheet dropped onto a collider with keyframes at two frames, and a
// curtain pinned along its top edge pulled aside.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/optimize_job.h"
#include "bench/bench_reachable.h"
#include "core/error.h"
#include "../support/interrupted_run.h"
#include "../sim/character_test_util.h"

namespace kf {
namespace {
namespace fs = std::filesystem;
using test::run_keyframe_interrupted;
using nlohmann::json;

// The run's worst keyframe miss (in tolerances) and its evaluations.
std::pair<double, int> worst_miss(const fs::path& run) {
  std::ifstream in(run / "report.json");
  const json report = json::parse(in);
  double worst = 0;
  for (const json& k : report.at("keyframe_errors")) worst = std::max(worst, k.at("miss_after").get<double>());
  return {worst, report.at("evaluations").get<int>()};
}

void expect_budget_run_ends_at_least_as_close(const std::string& kind, int index) {
  constexpr int kBudget = 60;
  test::TempDir dir;
  ReachableScene r = generate_reachable(kind, 52, index, true, dir.path());
  // Every stage runs to its budget (as the figure scenes do), so the full-budget run is still in its plan at
  // its 60th evaluation rather than finished.
  r.scene["optimizer"]["stop_when_reached"] = false;
  r.scene["optimizer"]["max_evaluations"] = kBudget;
  std::ofstream(dir.path() / "budget.json") << r.scene.dump(1);
  r.scene["optimizer"]["max_evaluations"] = 300;
  std::ofstream(dir.path() / "full.json") << r.scene.dump(1);
  const int budget_code = run_keyframe_interrupted(dir.path(), {"optimize", "budget.json", "--out", "budget"});
  EXPECT_TRUE(budget_code == 0 || budget_code == kExitNotReached) << budget_code;
  const int cut_code = run_keyframe_interrupted(dir.path(), {"optimize", "full.json", "--out", "cut"}, kBudget);
  EXPECT_TRUE(cut_code == 0 || cut_code == kExitNotReached || cut_code == kExitInterrupted) << cut_code;
  const auto [budget_miss, budget_evaluations] = worst_miss(dir.path() / "budget");
  const auto [cut_miss, cut_evaluations] = worst_miss(dir.path() / "cut");
  EXPECT_LE(budget_evaluations, kBudget);
  // The signal is sent after the 60th evaluation's line; one more evaluation may finish before it lands, which
  // only favours the cut run.
  EXPECT_LE(cut_evaluations, kBudget + 1);
  EXPECT_LE(budget_miss, std::max(cut_miss, 1.0)) << "budget " << budget_miss << " tolerances after " << budget_evaluations
                                                  << " evaluations; cut full run " << cut_miss << " after " << cut_evaluations;
  std::cout << kind << "-" << index << ": budget " << budget_miss << " after " << budget_evaluations << ", cut " << cut_miss
      << " after " << cut_evaluations << std::endl;
}

TEST(StrategyBudgetJob, ATwoKeyframeDropWithSixtyEvaluationsEndsAtLeastAsCloseAsACutFullRun) {
  expect_budget_run_ends_at_least_as_close("drop-collider", 1);
}

TEST(StrategyBudgetJob, APinnedCurtainWithSixtyEvaluationsEndsAtLeastAsCloseAsACutFullRun) {
  expect_budget_run_ends_at_least_as_close("hang-edge", 1);
}

}  // namespace
}  // namespace kf
