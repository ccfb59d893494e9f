#pragma once
// The last step of a run that ended with a keyframe unmet but near: Gauss–Newton onto the keyframes from the
// run's best point (opt/keyframe_projection.h), for every control kind, within a bounded number of
// simulations and adjoint passes. L-BFGS on keyframes plus effort ends a few tolerances short when the effort
// holds the keyframe back or the objective is flat along what is left; the minimum-norm step on the residuals
// alone is the smallest change of the controls that meets them.
#include <atomic>
#include <vector>

#include "opt/keyframe_projection.h"

namespace kf {

struct NearMissRule {
  double near_limit = 1.5;     // tried when the worst keyframe is at most this many tolerances off
  double reach_share = 0.8;    // and done when every keyframe is within this share of its tolerance
  // Passes allowed: two per evaluation the run has left (a simulation and an adjoint pass), and at least
  // this share of the scene's max_evaluations. 0: the run's own budget bounds the effort (a run that spent
  // it is left as it ended); tests/results/reachable/README.md ("Near misses") has what a floor bought.
  double min_share = 0.0;
  bool backtrack = true;  // ProjectionOptions::backtrack
};

// The passes a projection after a run gets: `left` evaluations unspent of the scene's `max_evaluations`.
int near_miss_passes(const NearMissRule& rule, int left, int max_evaluations);

// The worst placed keyframe's distance in tolerances at the problem's last rollout (every state kept), as the
// projection measures it; 0 when no keyframe places particles.
double near_miss_worst(Problem& problem, const Scene& scene);

// From z, the problem's controls at the run's end (its held step schedule held), with `unmet` the scene's
// keyframes the run left outside their tolerance: the unmet keyframes first, then all
// (project_unmet_then_all). kNotApplicable when none is unmet, kFar when the worst is not near.
KeyframeProjection project_near_miss(Problem& problem, const Scene& scene, const VecX& z,
                                     const std::vector<bool>& unmet, int passes, const NearMissRule& rule,
                                     const std::atomic<bool>* stop);

}  // namespace kf
