// A near miss at the default budget whose effort holds its keyframe back (opt/budget_extension.h): who gets a
// stage more, how many evaluations, what bounds them, and what a run not extended is told.
#include <gtest/gtest.h>

#include <string>

#include "opt/budget_extension.h"

namespace kf {
namespace {

// A 18 x 18 sheet thrown over 31 steps that stopped at the default 300 evaluations 1.24 tolerances off, the
// effort 80 % of its objective (throw-0 of the generated suite).
BudgetExtensionFacts thrown_near_miss() {
  BudgetExtensionFacts f;
  f.budget_stop = true;
  f.worst_miss = 1.24;
  f.effort_share = 0.8;
  f.budget = 300;
  f.particle_steps = 324 * 31;
  return f;
}

bool says(const BudgetExtension& e, const std::string& what) { return e.why.find(what) != std::string::npos; }

TEST(BudgetExtension, AnEffortBoundNearMissGetsTheEvaluationsItsCostAllows) {
  const BudgetExtensionRule rule;
  const BudgetExtension e = plan_budget_extension(rule, thrown_near_miss());
  EXPECT_TRUE(e.considered);
  EXPECT_EQ(e.evaluations, 79);  // 0.8e6 particle-steps over 10044 a simulation, under a third of 300
  EXPECT_LE(e.evaluations * thrown_near_miss().particle_steps, rule.max_particle_steps);
  EXPECT_TRUE(says(e, "extended by 79 evaluations")) << e.why;
  EXPECT_TRUE(says(e, "effort 80 % of the objective")) << e.why;
  BudgetExtensionFacts small = thrown_near_miss();
  small.particle_steps = 100;  // a cheap sheet: the share of the default budget binds
  EXPECT_EQ(plan_budget_extension(rule, small).evaluations, 100);
}

TEST(BudgetExtension, AStatedBudgetAMetRunOrAnEarlyEndIsNeverConsidered) {
  const BudgetExtensionRule rule;
  BudgetExtensionFacts stated = thrown_near_miss();
  stated.stated = true;
  EXPECT_FALSE(plan_budget_extension(rule, stated).considered);
  EXPECT_EQ(plan_budget_extension(rule, stated).evaluations, 0);
  BudgetExtensionFacts met = thrown_near_miss();
  met.met = true;
  EXPECT_FALSE(plan_budget_extension(rule, met).considered);
  BudgetExtensionFacts early = thrown_near_miss();
  early.budget_stop = false;  // converged or stalled: opt/keyframe_weights.h's rule has its evaluations
  EXPECT_FALSE(plan_budget_extension(rule, early).considered);
  EXPECT_TRUE(plan_budget_extension(rule, early).why.empty());
}

// Considered and declined, each with its reason: too far, an effort that is not what holds the keyframe
// back (a dropped sheet's forces), or a sheet whose simulations are too dear for even a few evaluations.
TEST(BudgetExtension, FarSmallEffortOrDearRunsAreNotExtendedAndSayWhy) {
  const BudgetExtensionRule rule;
  BudgetExtensionFacts far = thrown_near_miss();
  far.worst_miss = 2.5;
  BudgetExtension e = plan_budget_extension(rule, far);
  EXPECT_TRUE(e.considered);
  EXPECT_EQ(e.evaluations, 0);
  EXPECT_TRUE(says(e, "not extended: the worst keyframe is 2.5 tolerances off, over 2")) << e.why;
  BudgetExtensionFacts forces = thrown_near_miss();
  forces.effort_share = 4e-4;
  e = plan_budget_extension(rule, forces);
  EXPECT_EQ(e.evaluations, 0);
  EXPECT_TRUE(says(e, "the effort is 0 % of the objective, below 50 %")) << e.why;
  BudgetExtensionFacts dear = thrown_near_miss();
  dear.particle_steps = 1e5;
  e = plan_budget_extension(rule, dear);
  EXPECT_EQ(e.evaluations, 0);
  EXPECT_TRUE(says(e, "allows 8 evaluations, fewer than 12")) << e.why;
  BudgetExtensionFacts large = thrown_near_miss();
  large.particle_steps = 676 * 40;  // a 26 x 26 sheet over 40 steps (throw-18): 29 evaluations
  EXPECT_EQ(plan_budget_extension(rule, large).evaluations, 29);
}

}  // namespace
}  // namespace kf
