#pragma once
// A near miss at the default budget whose effort holds its keyframe back gets a bounded stage more with that
// keyframe's weight raised. A thrown sheet's per-particle stage spends its evaluations where the effort of its
// initial velocities is most of the objective: L-BFGS then mostly lowers the effort, the keyframe term falls
// slowly, and a larger budget barely brings it in (tests/results/reachable/near/). The keyframes-are-met rule
// (opt/keyframe_weights.h) raises a missed keyframe's weight only after a stage that ended early with
// evaluations left, never after a budget stop. So when the scene did not state max_evaluations (its default
// is the strategy's to spend), the last stage stopped at its limit with a keyframe within a few tolerances
// and the effort at least half of the objective, one stage of the same controls follows with the unmet
// keyframes' weights raised, its evaluations bounded by a share of the default budget and by a cost in
// particle-steps so a scene stays within the time the suite allows. Decided from evaluation counts and
// objective values only, never from wall time. A run that met its keyframes, a scene that states
// max_evaluations (its cap is kept exactly) and a run given --max-evaluations are never extended.
#include <string>

namespace kf {

struct BudgetExtensionRule {
  double near_limit = 2.0;        // the worst keyframe at most this many tolerances off
  double min_effort_share = 0.5;  // the effort at least this share of the objective (at the scene's weights)
  double max_share = 1.0 / 3.0;   // at most this share of the default budget more
  double max_particle_steps = 0.8e6;  // and at most this many particle-steps simulated (particles x steps each)
  int min_evaluations = 12;       // fewer than these would not get past a line search's first trials
};

// What the run shows when its stages are done.
struct BudgetExtensionFacts {
  bool stated = false;        // the scene states optimizer.max_evaluations, or the command gave the budget
  bool budget_stop = false;   // the last stage stopped at its evaluation limit
  bool met = false;           // every keyframe within its tolerance
  double worst_miss = 0;      // the worst keyframe's error over its tolerance
  double effort_share = 0;    // the effort over the objective at the run's best point, at the scene's weights
  int budget = 0;             // optimizer.max_evaluations
  double particle_steps = 0;  // one simulation's particles x steps
};

struct BudgetExtension {
  int evaluations = 0;      // granted (0: not extended)
  bool considered = false;  // a near miss at its default budget: `why` says what was decided
  std::string why;          // one line for the log and the run's status
};

BudgetExtension plan_budget_extension(const BudgetExtensionRule& rule, const BudgetExtensionFacts& facts);

}  // namespace kf
