#pragma once
// The adjoint gradient against central finite differences on a sample of control coordinates.
//
// Each sampled coordinate gets central differences at three steps, eps, eps/10 and eps/100 (relative to
// max(1, |z_i|)). Where φ is smooth, adjacent ones agree to O(step²); where a kink or a jump of φ (a
// contact starting, a step split differently) lies within the steps they do not, and where the step is
// small round-off takes over. The adjacent pair that agrees better is used: its relative disagreement is
// the sample's spread, and its Richardson extrapolation, fd(fine) + (fd(fine) - fd(coarse)) / 99, the
// sample's derivative (it cancels the O(step²) error of a strongly curved φ). A sample whose spread
// exceeds kink_tolerance is counted as a kink and left out of the error measures: neither difference is a
// derivative there. fd_spread, the largest spread of the checked samples, is the resolution of the check:
// an adjoint error below it cannot be seen.
#include <nlohmann/json.hpp>

#include "opt/problem.h"

namespace kf {

struct GradcheckOptions {
  int samples = 40;
  double eps = 1e-4;              // the larger of the two steps, relative to max(1, |z_i|)
  double kink_tolerance = 1e-2;   // spread beyond which a sample is a kink
  unsigned seed = 7;
};

struct GradcheckResult {
  int checked = 0;             // coordinates compared (kinks excluded)
  int kinks = 0;               // samples whose two differences disagree beyond kink_tolerance
  double max_rel_error = 0;    // max |adjoint − fd| / max(|fd|, floor) over the checked samples (fd: Richardson)
  double cosine = 0;           // between the checked adjoint and finite-difference vectors
  double rel_error_norm = 0;   // ‖adjoint − fd‖ / ‖fd‖ over the checked samples
  double fd_spread = 0;        // max |fd(eps) − fd(eps/10)| / max(|fd(eps/10)|, floor) over the checked samples
  double floor = 0;            // 1e-3 × the largest sampled |fd|: smaller components are round-off
  double grad_norm = 0;        // ‖dφ/dz‖ over all coordinates
  double phi = 0;
  double eps = 0;
  nlohmann::json to_json() const;
};

// Checks at z (size problem.size()), preferring coordinates whose adjoint gradient is not negligible so the
// check cannot pass on zeros: half the sample is the largest components, half chosen at random with `seed`.
GradcheckResult gradcheck(Problem& problem, const VecX& z, const GradcheckOptions& options);

}  // namespace kf
