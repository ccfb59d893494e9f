#pragma once
// A cloth keyframe problem as residuals: where the keyframes that place the sheet's particles (a position
// keyframe's targets, a centre of mass) want them at their steps, three numbers per particle or centroid.
// What a Gauss–Newton or Levenberg–Marquardt step works on (opt/rigid_throw_fit.h, opt/keyframe_projection.h).
#include <vector>

#include "adjoint/rollout.h"
#include "core/types.h"
#include "opt/problem.h"
#include "scene/scene.h"

namespace kf {

// One keyframe the residuals hold: where the sheet's particles should be at a step.
struct PlacedKeyframe {
  size_t objective = 0;       // its index in scene.objectives
  int step = 0;
  std::vector<int> ids;
  std::vector<Vec3> targets;  // one per id, or one for all; with `centroid`, the centroid's
  bool centroid = false;
  double root_weight = 1;     // √(w · scale): ½‖r‖² (weighted) is the term φ sums
  int rows() const { return 3 * (centroid ? 1 : int(ids.size())); }
};

// The keyframes of `scene` that place particles, with a positive weight at `problem`'s weight scales.
// `all_placed`, when given, says whether every keyframe with a positive weight is among them.
std::vector<PlacedKeyframe> placed_keyframes(Problem& problem, const Scene& scene, bool* all_placed = nullptr);

int residual_count(const std::vector<PlacedKeyframe>& placed);

// The residuals of the rollout into r (sized residual_count), weighted by root_weight when `weighted`, and
// each keyframe's distance (RMS over its particles, or the centroid's; m) into `distances` when given.
// Returns the largest distance.
double keyframe_residuals(const Rollout& rollout, const std::vector<PlacedKeyframe>& placed, bool weighted, VecX& r,
                          std::vector<double>* distances = nullptr);

// A combination wᵀr of the residuals (unweighted) as a StateCost: its adjoint pass gives wᵀ dr/dz (a unit w:
// one row of the Jacobian).
class ResidualCombination : public StateCost {
 public:
  ResidualCombination(const std::vector<PlacedKeyframe>& placed, const VecX& w) : placed_(placed), w_(w) {}
  bool active(int n) const override;
  double eval(int n, const VecX& x, const VecX& v, VecX& gx, VecX& gv) const override;

 private:
  const std::vector<PlacedKeyframe>& placed_;
  const VecX& w_;
};

// The residuals of a problem's controls and their derivatives: flies z with its tape kept, then gives
// wᵀ dr/dz by one adjoint pass over that flight. Every flight is under the system's held step schedule.
class ResidualFlight {
 public:
  ResidualFlight(Problem& problem, std::vector<PlacedKeyframe> placed);
  int rows() const { return int(r_.size()); }
  const std::vector<PlacedKeyframe>& placed() const { return placed_; }
  // Simulates z; false when it diverged or a residual is not finite. Then residuals() (unweighted, m) and
  // worst() (the largest keyframe distance, m) describe it.
  bool fly(const VecX& z);
  const VecX& residuals() const { return r_; }
  double worst() const { return worst_; }
  // wᵀ dr/dz at the last flight (which must not have diverged), into g (the problem's size).
  bool transpose_times(const VecX& w, VecX& g);
  int simulations() const { return simulations_; }
  int adjoint_passes() const { return adjoint_passes_; }

 private:
  Problem& problem_;
  std::vector<PlacedKeyframe> placed_;
  VecX x0_, v0_, u_, dx0_, dv0_, z_;
  StepControl u_at_;
  Rollout rollout_;
  VecX r_;
  double worst_ = 0;
  int simulations_ = 0, adjoint_passes_ = 0;
};

}  // namespace kf
