#pragma once
// Levenberg–Marquardt (opt/few_variable_fit.h) on the six rigid throw variables (Δv, ω) of a thrown sheet. A
// generated throw differs from its scene's by a rigid Δv + ω × r, so an exact rigid solution exists, but the
// throw search's evenly spread throws only land near it and the rigid stage's L-BFGS, seeing one scalar, crawls
// along the narrow valley a spin and a velocity make together; a Jacobian is twelve flights.
#include <atomic>
#include <string>
#include <vector>

#include "core/types.h"
#include "opt/few_variable_fit.h"
#include "opt/problem.h"
#include "scene/scene.h"

namespace kf {

using RigidFitStop = FitStop;

struct RigidThrowFit {
  VecX z;                   // the best rigid controls (Δv, ω) found over every start
  double cost = 0;          // ½‖r‖² there: the placed keyframe terms as φ weighs them (weight scales included)
  double worst_miss = 0;    // the largest keyframe distance there (RMS over its particles; m) over its tolerance
  int simulated = 0;        // flights, Jacobians' included
  int starts = 0;           // starts fitted from
  std::vector<RigidFitStop> stops;   // how the fit from each start ended
  std::vector<double> start_costs;   // ½‖r‖² at each start
  std::vector<double> end_costs;     // and where each ended
  bool reached() const { return !stops.empty() && stops.back() == RigidFitStop::kReached; }
};

// The options' scales are set by the fit (a spin times the sheet's radius): leave them empty.
using RigidFitOptions = FewFitOptions;

// Fits from each of `starts` in turn (rigid controls, 6 numbers each) until one reaches every placed
// keyframe, the flights allowed are spent or *stop is set; returns the best point of all.
// `problem` must have initial_rigid_velocity controls; its last rollout is left at an arbitrary point.
RigidThrowFit fit_rigid_throw(Problem& problem, const Scene& scene, const std::vector<VecX>& starts,
                              const RigidFitOptions& options);

// Adds the fit `more` (from other starts) to `into`: its starts, flights and, when better, its point.
void absorb(RigidThrowFit& into, const RigidThrowFit& more);

// One line for the run's log: the starts, how each ended, the flights and the worst miss reached.
std::string describe(const RigidThrowFit& fit);

}  // namespace kf
