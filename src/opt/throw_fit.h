#pragma once
// The rigid throw that carries a sheet through its keyframes in free flight: a candidate the throw search
// (opt/throw_search.h) simulates beside its evenly spread ones. A search box around the scene's throw holds
// few throws that also turn the sheet the way its keyframes do (a sheet turned over on its way through a
// ring); the keyframes themselves say how far it turns and by when.
#include <optional>
#include <vector>

#include "adjoint/rollout.h"
#include "core/types.h"
#include "scene/scene.h"

namespace kf {

class Problem;

// The rigid controls (Δv, ω) of Controls' initial_rigid_velocity kind, relative to the scene's initial
// velocities x0, v0 (one Vec3 per particle), whose ballistic motion under the cloth's gravity and linear air
// drag best meets the keyframes: the mean velocity by least squares on the centre of mass each keyframe
// implies, the spin by least squares on the turns between successive keyframes that fix an orientation
// (a position keyframe on three or more particles; each turn under half a revolution). Empty when no
// keyframe implies a centre of mass, or for a scene without cloth. With `flown` (a rollout of the scene's
// steps, every frame kept), the fit reads where the flown sheet's particles are at each keyframe instead
// of the targets: the throw that motion looks like.
std::optional<VecX> fit_throw(const Scene& scene, const VecX& x0, const VecX& v0, const Rollout* flown = nullptr);

// The fitted throw corrected by shooting: a cloth turns and sags unlike a rigid body (and its integrator
// damps the turn), so the fitted throw misses by what the fit reads off its own flight; each correction
// flies the throw and adds the difference between the fit of the targets and the fit of that flight.
// Returns the best of the `corrections` + 1 throws flown and its objective (no z: nothing to fit or every
// flight diverged). `problem` must have initial_rigid_velocity controls.
struct FittedThrow {
  std::optional<VecX> z;
  double phi = 0;
  int simulated = 0;
  std::vector<double> flown;  // the objective of each throw flown, the fitted one first
};
FittedThrow refine_fitted_throw(Problem& problem, const Scene& scene, int corrections);

}  // namespace kf
