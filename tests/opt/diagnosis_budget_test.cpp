// A run stopped at its budget says what more evaluations are expected to bring, whatever cause the diagnosis
// names (opt/diagnosis.h), when its progress says anything: the near misses of the generated suite stop at
// their budget in motion that amplifies perturbations, and their diagnoses named only the amplification.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "opt/diagnosis.h"

namespace kf {
namespace {

std::vector<KeyframeJudgement> missed_by(double miss) {
  KeyframeJudgement k;
  k.name = "center_of_mass@21";
  k.judged = true;
  k.miss_before = 8.3;
  k.miss_after = miss;
  k.error_before = "8.30 cm";
  k.error_after = "4.00 cm";
  k.tolerance = "1.00 cm";
  return {k};
}

// 300 evaluations, the keyframe terms from 10 to 1 (progress), the last tenth falling `rate`.
RunFacts at_budget(double rate, const std::string& status = "evaluation limit reached") {
  RunFacts f;
  f.status = status;
  f.budget = status.find("limit reached") != std::string::npos;
  f.keyframe_objective_start = f.objective_start = f.max_objective = 10;
  f.keyframe_objective_end = 1;
  f.evaluations = 300;
  f.recent_improvement = rate;
  return f;
}

Sensitivity amplifying() {
  Sensitivity s;
  s.phi = 15;
  s.phi_noise = 1e-14;
  s.growth = s.growth_beyond_free = 1.2e5;
  s.grows_from_frame = 4;
  return s;
}

int count(const std::string& line, const std::string& what) {
  int n = 0;
  for (size_t at = line.find(what); at != std::string::npos; at = line.find(what, at + 1)) ++n;
  return n;
}

// Miss 4 tolerances: the keyframe terms 16x lower; at 2x a tenth (30 evaluations) that is 4 tenths, 120.
TEST(DiagnosisBudget, AnAmplifyingRunAtItsBudgetStatesTheEvaluationsItExpectsToNeed) {
  const std::string line = diagnose(missed_by(4), amplifying(), at_budget(0.5)).line;
  EXPECT_NE(line.find("amplifies perturbations"), std::string::npos) << line;
  EXPECT_NE(line.find("it stopped at its budget"), std::string::npos) << line;
  EXPECT_NE(line.find("over the last tenth of its 300 evaluations (2x), the worst keyframe needs about 120 more "
                      "evaluations"),
            std::string::npos)
      << line;
}

// The whole run's last tenth may begin in an earlier stage whose objective is lower only because its weights or
// control kind differ (throw-0: its lattice stage's 3.5e-4 against its per-particle stage's 1.15e-3): a best
// objective that did not fall over it says nothing of the last stage's progress, and the line adds nothing.
TEST(DiagnosisBudget, ARunAtItsBudgetWhoseBestDidNotFallAddsNoEstimate) {
  const std::string line = diagnose(missed_by(1.24), amplifying(), at_budget(1.0)).line;
  EXPECT_NE(line.find("it stopped at its budget"), std::string::npos) << line;
  EXPECT_EQ(line.find("needs about"), std::string::npos) << line;
  EXPECT_EQ(line.find("not expected"), std::string::npos) << line;
  EXPECT_EQ(line.find("too few"), std::string::npos) << line;
}

// A few evaluations that did not fall over their last tenth (a line search's trials) say nothing of how many
// more the run needs, whichever cause is named.
TEST(DiagnosisBudget, AFewEvaluationsThatDidNotFallAreTooFewToTell) {
  RunFacts few = at_budget(1.0);
  few.evaluations = 15;
  const std::string amplified = diagnose(missed_by(2.2), amplifying(), few).line;
  EXPECT_NE(amplified.find("did not fall over the last tenth of its 15 evaluations, too few evaluations to tell how "
                           "many more it needs"),
            std::string::npos)
      << amplified;
  EXPECT_EQ(amplified.find("not expected to reach it"), std::string::npos) << amplified;
  Sensitivity smooth;
  smooth.growth = smooth.growth_beyond_free = 1.5;
  const std::string budget = diagnose(missed_by(2.2), smooth, few).line;
  EXPECT_NE(budget.find("cause: its budget ended it after 15 evaluations (the objective did not fall over the last "
                        "tenth of them, too few evaluations to tell how many more it needs)"),
            std::string::npos)
      << budget;
  EXPECT_EQ(budget.find("still fell 1x"), std::string::npos) << budget;
}

// Said once: where the budget is the cause named, its own sentence has the estimate.
TEST(DiagnosisBudget, TheEstimateIsSaidOnceAndOnlyForABudgetStop) {
  Sensitivity smooth;
  smooth.growth = smooth.growth_beyond_free = 1.5;
  const std::string budget = diagnose(missed_by(4), smooth, at_budget(0.5)).line;
  EXPECT_NE(budget.find("cause: its budget ended it"), std::string::npos) << budget;
  EXPECT_EQ(count(budget, "needs about 120 more"), 1) << budget;
  const std::string stalled = diagnose(missed_by(4), amplifying(), at_budget(0.5, "converged")).line;
  EXPECT_EQ(stalled.find("needs about"), std::string::npos) << stalled;
  EXPECT_EQ(stalled.find("no longer fell"), std::string::npos) << stalled;
  EXPECT_TRUE(diagnose(missed_by(0.9), amplifying(), at_budget(0.5)).reached);
}

}  // namespace
}  // namespace kf
