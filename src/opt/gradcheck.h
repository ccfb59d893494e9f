#pragma once
// The adjoint gradient against central finite differences on a sample of control coordinates.
//
// Each sampled coordinate gets central differences at steps 4 eps, 2 eps, eps, eps/2, ... (relative to
// max(1, |z_i|)); each adjacent pair is Richardson-extrapolated, and three times the change between two
// successive extrapolations plus their round-off (phi_noise / step) is the estimate's error. The steps
// shrink until that error is below 1e-9 of the value, or until φ's round-off explains the changes for
// three levels in a row, or to eps/2^13; the best estimate is kept. So the check adapts to φ's curvature (a stiff contact can need steps a hundred times below eps
// before the differences converge) and to φ's round-off (which floors any fixed small step). Where a kink
// or a jump of φ (a contact feature changing, a step split differently) lies within every step the
// estimates never agree, and a sample whose relative error estimate exceeds kink_tolerance is counted as
// a kink and left out of the error measures: no difference is a derivative there. fd_spread, the largest
// relative error estimate of the checked samples, is the resolution of the check: an adjoint error below
// it cannot be seen.
#include <functional>

#include <nlohmann/json.hpp>

#include "opt/problem.h"

namespace kf {

struct GradcheckOptions {
  int samples = 40;
  double eps = 1e-4;              // the step completing the first extrapolation (differences start at 4 eps)
  double kink_tolerance = 1e-2;   // relative error estimate beyond which a sample is a kink
  unsigned seed = 7;
};

struct GradcheckResult {
  int checked = 0;             // coordinates compared (kinks excluded)
  int kinks = 0;               // samples whose differences never agree to kink_tolerance
  double max_rel_error = 0;    // max |adjoint − fd| / max(|fd|, floor) over the checked samples (fd: extrapolated)
  double cosine = 0;           // between the checked adjoint and finite-difference vectors
  double rel_error_norm = 0;   // ‖adjoint − fd‖ / ‖fd‖ over the checked samples
  double fd_spread = 0;        // max error estimate / max(|fd|, floor) over the checked samples
  double floor = 0;            // 1e-3 × the largest sampled |fd|: smaller components are round-off
  double grad_norm = 0;        // ‖dφ/dz‖ over all coordinates
  double phi = 0;
  double phi_noise = 0;        // φ's round-off near z (second differences along a random direction)
  double eps = 0;
  // The simulation diverged at z (at this step): φ is the large finite stand-in, no gradient exists and
  // nothing was compared; the error measures are then null in to_json, not 0.
  bool diverged = false;
  int diverged_at = -1;
  nlohmann::json to_json() const;
};

// Checks at z (size problem.size()), preferring coordinates whose adjoint gradient is not negligible so the
// check cannot pass on zeros: half the sample is the largest components, half chosen at random with `seed`.
// The derivative from central(h), a central difference at step h, for h = step, step/2, ... as above;
// stops early once error <= target * |value|. noise: φ's round-off; a difference at step h carries about
// noise / h of it, which the error estimate includes.
struct DifferenceEstimate {
  double value, error;
};
DifferenceEstimate extrapolated_difference(double step, const std::function<double(double)>& central,
                                           double target, double noise);

// At controls under which the simulation diverges, returns with `diverged` set and nothing compared.
GradcheckResult gradcheck(Problem& problem, const VecX& z, const GradcheckOptions& options);

// The round-off σ of φ near z (φ = φ(z), already evaluated): φ along a random direction (from `seed`) at steps
// of 1e-9 max(1, |z|∞), so small that φ is linear there; its second differences are then round-off alone
// (each has variance 6σ²). Where φ is no function of z at that scale (a bifurcation) it is φ's jitter.
double phi_noise(Problem& problem, const VecX& z, double phi, unsigned seed);

}  // namespace kf
