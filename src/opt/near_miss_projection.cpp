#include "opt/near_miss_projection.h"

#include <algorithm>
#include <cmath>

#include "opt/keyframe_residuals.h"
#include "opt/keyframes/keyframe_common.h"

namespace kf {

int near_miss_passes(const NearMissRule& rule, int left, int max_evaluations) {
  return std::max(2 * std::max(0, left), int(std::lround(rule.min_share * max_evaluations)));
}

double near_miss_worst(Problem& problem, const Scene& scene) {
  const std::vector<PlacedKeyframe> placed = placed_keyframes(problem, scene);
  if (placed.empty() || !scene.cloth) return 0;
  VecX r(residual_count(placed));
  return keyframe_residuals(problem.rollout(), placed, false, r) / cloth_tolerance(scene);
}

KeyframeProjection project_near_miss(Problem& problem, const Scene& scene, const VecX& z,
                                     const std::vector<bool>& unmet, int passes, const NearMissRule& rule,
                                     const std::atomic<bool>* stop) {
  KeyframeProjection none;
  none.z = z;
  if (std::none_of(unmet.begin(), unmet.end(), [](bool u) { return u; })) return none;
  ProjectionOptions o;
  o.max_passes = passes;
  o.reach_share = rule.reach_share;
  o.near_limit = rule.near_limit;
  o.stop = stop;
  o.backtrack = rule.backtrack;
  o.sketch = true;
  return project_unmet_then_all(problem, scene, z, unmet, o);
}

}  // namespace kf
