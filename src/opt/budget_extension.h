#pragma once
// The default budget extended while the keyframes are near. A run whose last stage stopped at its evaluation
// limit with a keyframe a little outside its tolerance, and still falling, often needs only a few tens of
// evaluations more; at the default optimizer.max_evaluations it would stop there and report a near miss. When
// the scene did not state max_evaluations, one more stage of the scene's own controls follows, with the
// evaluations the run's own rate of progress says it needs (opt/diagnosis.h's expected_more_evaluations)
// and some margin, bounded by a share of the default budget and by a cost in particle-steps, so every scene
// stays within the time the suite allows. Decided from evaluation counts and objective values only, never
// from wall time: the same scene extends the same way on any machine and thread count. A run that met its
// keyframes, a scene that states max_evaluations (its cap is kept exactly) and a run given
// --max-evaluations are never extended.
#include <string>
#include <vector>

namespace kf {

struct BudgetExtensionRule {
  double near_limit = 2.0;   // the worst keyframe at most this many tolerances off
  double margin = 1.5;       // the evaluations granted: the expected ones times this
  int min_evaluations = 12;  // and at least these (a stage's line search needs a few trials to start)
  double max_share = 1.0;    // at most this share of the default budget more
  // At most this many particle-steps simulated in the extension (each evaluation: a simulation and its
  // adjoint pass over particles x steps).
  double max_particle_steps = 1.2e6;
};

// What the run shows when its stages are done.
struct BudgetExtensionFacts {
  bool stated = false;       // the scene states optimizer.max_evaluations, or the command gave the budget
  bool budget_stop = false;  // the last stage stopped at its evaluation limit
  bool met = false;          // every keyframe within its tolerance
  double worst_miss = 0;     // the worst keyframe's error over its tolerance
  int expected = 0;          // evaluations the rate says it still needs (0: not falling)
  int budget = 0;            // optimizer.max_evaluations
  double particle_steps = 0;  // one simulation's particles x steps
};

struct BudgetExtension {
  int evaluations = 0;  // granted (0: not extended)
  bool considered = false;  // the run ended near at its default budget: `why` says what was decided
  std::string why;      // one line for the log and the run's status
};

BudgetExtension plan_budget_extension(const BudgetExtensionRule& rule, const BudgetExtensionFacts& facts);

// The best objective at the end of `phis` (one stage's evaluations in order) over the best a tenth of them
// earlier: RunFacts::recent_improvement measured on one stage (1 when it did not fall, or too few).
double recent_improvement(const std::vector<double>& phis);

}  // namespace kf
