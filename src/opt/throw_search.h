#pragma once
// A global search over rigid throws, before the rigid throw's L-BFGS. A thrown sheet's objective has basins
// no gradient leaves: a towel that misses its rail lies on the ground under it, as near the target as it
// gets there, and every small change of the throw leaves it lying there. The search simulates throws spread
// evenly over a box around the scene's own (a Halton sequence: the same throws on every run), forward only,
// and the rigid stage starts from the best of them, the scene's throw and the throw fitted to the keyframes
// (opt/throw_fit.h); the boxes after the first are centred on the best so far.
#include <atomic>

#include "core/types.h"
#include "opt/problem.h"
#include "opt/rigid_throw_fit.h"
#include "opt/throw_fit.h"

namespace kf {

struct ThrowSearch {
  VecX z;                  // the best rigid controls (Δv, ω); zero: the scene's throw was best
  double phi = 0;          // their objective
  double start_phi = 0;    // the scene's throw's
  int simulated = 0;       // throws simulated besides the scene's (the fitted one among them)
  std::vector<double> fitted;  // the objectives of the fitted throw and its corrections (opt/throw_fit.h)
  double speed = 0;        // the box's half-width in Δv (m/s)
  double spin = 0;         // and in ω (rad/s)
  bool met = false;        // it ended early at a throw that meets every keyframe within half its tolerance
  std::optional<RigidThrowFit> rigid;  // Levenberg–Marquardt on (Δv, ω) after the search (search_and_fit_throws)
  std::vector<VecX> best_throws;       // the search's own best few throws (kFitStarts at most), lowest φ first
};

// The k-th element (k >= 1) of the van der Corput sequence in base b: the digits of k mirrored about the point.
// Bases 2, 3, 5, ... side by side give Halton's points, which fill a box evenly (the search's throws).
double radical_inverse(int k, int b);

// The fit after the search starts from this many of its best throws (one on a flight beyond kLargeFlight).
constexpr int kFitStarts = 4;

// A flight of more particle-steps than this is a large sheet's: the plan spends fewer evaluations on it.
constexpr double kLargeFlight = 12000;

// 1 up to kLargeFlight particle-steps a flight, then kLargeFlight over its particle-steps: a flight of
// kLargeFlight particle-steps over this one in cost, before the solver's iterations a step grow with the sheet.
double large_flight_share(int particles, int steps);

// How many throws the automatic search simulates for a sheet of `particles` over `steps` steps: about four
// million particle-steps, fewer for a flight of more than 12000 (times (12000 / its particle-steps)²), between
// 32 and 512 throws.
int automatic_throw_count(int particles, int steps);

// `problem` must have initial_rigid_velocity controls. The box: Δv within ±max(1 m/s, half the scene's mean
// initial speed) on each axis, ω within ± that over the sheet's RMS radius (rim speeds alike).
// `fitted` (refine_fitted_throw's, already flown) competes with the others and counts among the simulated.
// A set *stop ends the search after the throw being simulated, with the best so far. With `scene`, the search
// ends at a new best throw that puts every keyframe (each placing particles) within half its tolerance.
ThrowSearch search_throws(Problem& problem, int count, const FittedThrow& fitted = {},
                          const std::atomic<bool>* stop = nullptr, const Scene* scene = nullptr);

// What runs before a rigid first stage: Levenberg–Marquardt on the six rigid variables (opt/rigid_throw_fit.h)
// from the scene's throw and the throw fitted to the keyframes; when that does not bring every keyframe within
// half its tolerance (the search's own early end: the rigid stage judges the rest), the search
// (`count` throws less the fit's flights) and the fit again from each of its kFitStarts best throws, until
// one is within half of every tolerance (on a flight of more than kLargeFlight particle-steps from its best
// alone, as its time allows). A flight that lands on a collider or the ground is a rough function of the
// throw: the search's best often lies in another basin than the keyframes', and a runner-up in theirs
// (generated throw-0: its third best). Each fit flies at most a quarter of `count` (at most 100 the first);
// `budget` caps every flight together. The search's best, when it beats the scene's and the fitted throw,
// has its quarter as the one start it was; the other best throws share what is left evenly. A fit already
// within half of every tolerance ends it.
// The result's z is the best point of all, by φ.
ThrowSearch search_and_fit_throws(Problem& problem, const Scene& scene, int count, int budget,
                                  const std::atomic<bool>* stop = nullptr);

}  // namespace kf
