// The default budget extended while the keyframes are near (opt/budget_extension.h): who is extended, by how
// many evaluations, and what bounds it; and the rate one stage's objective fell at.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "opt/budget_extension.h"

namespace kf {
namespace {

// A run at the default 300 evaluations that stopped there 1.2 tolerances off, 40 evaluations short.
BudgetExtensionFacts near_at_budget() {
  BudgetExtensionFacts f;
  f.budget_stop = true;
  f.worst_miss = 1.2;
  f.expected = 40;
  f.budget = 300;
  f.particle_steps = 225 * 30;  // a 15 x 15 sheet over 30 steps
  return f;
}

TEST(BudgetExtension, ANearRunAtTheDefaultBudgetGetsWhatItsRateExpectsWithMargin) {
  const BudgetExtensionRule rule;
  const BudgetExtension e = plan_budget_extension(rule, near_at_budget());
  EXPECT_TRUE(e.considered);
  EXPECT_EQ(e.evaluations, 60);  // 40 expected x 1.5
  EXPECT_NE(e.why.find("extended by 60"), std::string::npos) << e.why;
  BudgetExtensionFacts few = near_at_budget();
  few.expected = 2;
  EXPECT_EQ(plan_budget_extension(rule, few).evaluations, rule.min_evaluations);
}

TEST(BudgetExtension, AStatedBudgetAMetRunOrAStallIsNeverExtended) {
  const BudgetExtensionRule rule;
  BudgetExtensionFacts stated = near_at_budget();
  stated.stated = true;
  EXPECT_FALSE(plan_budget_extension(rule, stated).considered);
  EXPECT_EQ(plan_budget_extension(rule, stated).evaluations, 0);
  BudgetExtensionFacts met = near_at_budget();
  met.met = true;
  EXPECT_FALSE(plan_budget_extension(rule, met).considered);
  BudgetExtensionFacts stalled = near_at_budget();
  stalled.budget_stop = false;  // the last stage converged or its line search stalled
  EXPECT_FALSE(plan_budget_extension(rule, stalled).considered);
}

// Considered, and says why not: too far, no longer falling, or needing more than the bounds allow.
TEST(BudgetExtension, FarFlatOrCostlyRunsAreNotExtendedAndSayWhy) {
  const BudgetExtensionRule rule;
  BudgetExtensionFacts far = near_at_budget();
  far.worst_miss = 2.5;
  BudgetExtension e = plan_budget_extension(rule, far);
  EXPECT_TRUE(e.considered);
  EXPECT_EQ(e.evaluations, 0);
  EXPECT_NE(e.why.find("2.5 tolerances off, over 2"), std::string::npos) << e.why;
  BudgetExtensionFacts flat = near_at_budget();
  flat.expected = 0;
  e = plan_budget_extension(rule, flat);
  EXPECT_EQ(e.evaluations, 0);
  EXPECT_NE(e.why.find("no longer fell"), std::string::npos) << e.why;
  BudgetExtensionFacts slow = near_at_budget();
  slow.particle_steps = 1000;  // a small sheet: the share of the budget binds first
  slow.expected = 301;         // over the default budget again
  e = plan_budget_extension(rule, slow);
  EXPECT_EQ(e.evaluations, 0);
  EXPECT_NE(e.why.find("over the 300 an extension may take (a share of the budget)"), std::string::npos) << e.why;
  BudgetExtensionFacts large = near_at_budget();
  large.particle_steps = 26 * 26 * 40;  // 27040 a simulation: 44 evaluations within 1.2e6 particle-steps
  large.expected = 45;
  e = plan_budget_extension(rule, large);
  EXPECT_EQ(e.evaluations, 0);
  EXPECT_NE(e.why.find("over the 44 an extension may take (its cost in particle-steps)"), std::string::npos) << e.why;
}

// The margin never takes an extension past its bounds.
TEST(BudgetExtension, TheGrantStaysWithinTheCostBound) {
  const BudgetExtensionRule rule;
  BudgetExtensionFacts f = near_at_budget();
  f.particle_steps = 26 * 26 * 40;
  f.expected = 40;  // x 1.5 = 60, over the 44 the cost allows
  const BudgetExtension e = plan_budget_extension(rule, f);
  EXPECT_EQ(e.evaluations, 44);
  EXPECT_LE(e.evaluations * f.particle_steps, rule.max_particle_steps);
}

TEST(BudgetExtension, RecentImprovementIsTheBestAtTheEndOverTheBestATenthEarlier) {
  std::vector<double> phis;
  for (int i = 0; i < 100; ++i) phis.push_back(std::pow(0.99, i));
  EXPECT_NEAR(recent_improvement(phis), std::pow(0.99, 10), 1e-12);
  phis.push_back(INFINITY);  // a diverged trial counts for nothing
  phis.push_back(2.0);       // a worse trial keeps the best
  EXPECT_NEAR(recent_improvement(phis), std::pow(0.99, 99) / std::pow(0.99, 91), 1e-12);
  EXPECT_EQ(recent_improvement({1.0, 1.0, 1.0}), 1.0);
  EXPECT_EQ(recent_improvement({0.5}), 1.0);
}

}  // namespace
}  // namespace kf
