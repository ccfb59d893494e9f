// A stage still falling at its limit goes on with evaluations borrowed from the stages after it
// (opt/window_extension.h): when it goes on, how much each chunk borrows, and what the later stages keep.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <vector>

#include "opt/window_extension.h"

namespace kf {
namespace {

std::vector<EvaluationRecord> history_of(const std::vector<double>& phis) {
  std::vector<EvaluationRecord> h;
  for (double phi : phis) {
    EvaluationRecord r;
    r.evaluation = int(h.size()) + 1;
    r.phi = phi;
    h.push_back(r);
  }
  return h;
}

// φ falling by `rate` per evaluation (a steady descent), over n evaluations.
std::vector<double> geometric(int n, double rate) {
  std::vector<double> phis;
  double phi = 1.0;
  for (int k = 0; k < n; ++k, phi *= rate) phis.push_back(phi);
  return phis;
}

int sum(const std::vector<int>& v) { return std::accumulate(v.begin(), v.end(), 0); }

TEST(WindowExtension, LastTenthRatioIsBestAtEndOverBestBeforeTheLastTenth) {
  // 20 evaluations: the last tenth is the last 2; the best before them is 0.5, the best at the end 0.4.
  std::vector<double> phis(20, 0.6);
  phis[10] = 0.5;
  phis[18] = 0.45;
  phis[19] = 0.4;
  EXPECT_DOUBLE_EQ(last_tenth_ratio(history_of(phis)), 0.8);
  // A trial that rose does not count as a fall; a diverged one is skipped.
  phis[19] = 0.9;
  phis[18] = 0.7;
  EXPECT_DOUBLE_EQ(last_tenth_ratio(history_of(phis)), 1.0);
  std::vector<EvaluationRecord> h = history_of(geometric(30, 0.99));
  h.back().phi = 1e-9;
  h.back().diverged = true;
  EXPECT_NEAR(last_tenth_ratio(h), std::pow(0.99, 2), 1e-12);  // best at 28 over best at 26
  EXPECT_DOUBLE_EQ(last_tenth_ratio({}), 1.0);
}

TEST(WindowExtension, GoesOnOnlyAtItsLimitWhileFallingFasterThanTheThreshold) {
  const WindowExtensionRule rule;  // min_fall 0.5 %
  const auto falling = history_of(geometric(100, 0.998));  // ~2 % over the last 10
  const auto slow = history_of(geometric(100, 0.9998));    // ~0.2 %: a stalled window
  EXPECT_TRUE(still_falling_at_limit(StopReason::kEvaluationLimit, falling, rule));
  EXPECT_FALSE(still_falling_at_limit(StopReason::kEvaluationLimit, slow, rule));
  for (StopReason r : {StopReason::kConverged, StopReason::kLineSearchStalled, StopReason::kKeyframesReached,
                       StopReason::kInterrupted, StopReason::kTimeLimit})
    EXPECT_FALSE(still_falling_at_limit(r, falling, rule));
}

TEST(WindowExtension, ChunkIsTheStagesOwnShareWithinTheCapAndTheLaterFloors) {
  const WindowExtensionRule rule;  // share 1/2, floor 12, min_chunk 12
  // drop-collider-9's plan at 300 after its first window of 75: two more windows of its first keyframe, three
  // of its second (the first of them 75) and the whole horizon.
  const std::vector<int> later{30, 30, 75, 30, 30, 30};
  EXPECT_EQ(borrow_cap(later, rule), 112);
  EXPECT_EQ(chunk_to_borrow(75, 112, later, rule), 75);  // its own share first
  EXPECT_EQ(chunk_to_borrow(75, 37, later, rule), 37);   // then what the cap leaves
  EXPECT_EQ(chunk_to_borrow(75, 11, later, rule), 0);    // too few to be worth a fresh start
  // The later stages' floors bound it: two stages of 20 have 16 above their floors.
  EXPECT_EQ(chunk_to_borrow(75, 100, {20, 20}, rule), 16);
  EXPECT_EQ(chunk_to_borrow(75, 100, {12, 12, 13}, rule), 0);
}

TEST(WindowExtension, LendingTakesExactlyTheBorrowedAndKeepsEveryFloor) {
  const WindowExtensionRule rule;
  std::vector<int> later{30, 30, 75, 30, 30, 30};
  const int before = sum(later);
  lend(later, 75, rule);
  EXPECT_EQ(sum(later), before - 75);
  for (int m : later) EXPECT_GE(m, rule.floor_per_stage);
  // In proportion to what each had above its floor: the 75 gives most.
  EXPECT_GT(30 - later[0], 0);
  EXPECT_GT(75 - later[2], 2 * (30 - later[0]));
  lend(later, 37, rule);
  EXPECT_EQ(sum(later), before - 112);
  for (int m : later) EXPECT_GE(m, rule.floor_per_stage);
  // Everything above the floors, and a stage already below its floor keeps what it has.
  std::vector<int> low{5, 40, 13};
  lend(low, 29, rule);
  EXPECT_EQ(low, (std::vector<int>{5, 12, 12}));
  std::vector<int> none{50};
  lend(none, 0, rule);
  EXPECT_EQ(none, std::vector<int>{50});
}

TEST(WindowExtension, PlanInLimitsOutOverTwoChunks) {
  // drop-collider-9's plan at 300; its first window, still falling after each chunk, borrows 75, then 37 (the
  // cap is half of the 225 after it), then nothing; the run's total stays 300 and no stage before it changes.
  const WindowExtensionRule rule;
  std::vector<int> limits{75, 30, 30, 75, 30, 30, 30};
  StageBorrowing first(limits, 0, rule);
  EXPECT_EQ(first.next(limits), 75);
  EXPECT_EQ(first.next(limits), 37);
  EXPECT_EQ(first.next(limits), 0);
  EXPECT_EQ(first.borrowed(), 112);
  EXPECT_EQ(limits[0], 187);
  EXPECT_EQ(sum(limits), 300);
  for (size_t k = 1; k < limits.size(); ++k) EXPECT_GE(limits[k], rule.floor_per_stage);
  // A later window borrows only from the stages after it.
  std::vector<int> plan{75, 30, 30, 75, 30, 30, 30};
  StageBorrowing fourth(plan, 3, rule);
  EXPECT_EQ(fourth.next(plan), 45);  // half of the 90 after it
  EXPECT_EQ((std::vector<int>(plan.begin(), plan.begin() + 3)), (std::vector<int>{75, 30, 30}));
  EXPECT_EQ(plan[3], 120);
  EXPECT_EQ(sum(plan), 300);
  EXPECT_EQ(fourth.next(plan), 0);
  // The last stage has no one to borrow from.
  StageBorrowing last(plan, plan.size() - 1, rule);
  EXPECT_EQ(last.next(plan), 0);
  EXPECT_EQ(sum(plan), 300);
}

}  // namespace
}  // namespace kf
