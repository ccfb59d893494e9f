#pragma once
// Friction eased in by the strategy (opt/windows.h plans it, opt/strategy.h runs it). A particle sticking on
// a collider answers a force below its friction limit with a slip of eps / L per newton (sim/cloth/friction.h)
// and one above it by sliding: in the forces, the keyframe terms are flat, then steep, and a line search
// started in stick stalls where the sheet would still move once it slides. So a run on a scene with friction
// first optimises its stages with every friction coefficient scaled down, then the same stages at the
// scene's coefficients, warm-started from what the eased ones found.
#include "scene/scene.h"

namespace kf {

// Whether any contact of the scene has friction: a collider's, the sheet's on itself, a cape's on its body.
bool has_friction(const Scene& scene);

// The scene with every friction coefficient multiplied by `scale` (>= 0); sticking speeds unchanged.
Scene with_friction_scaled(const Scene& scene, double scale);

}  // namespace kf
