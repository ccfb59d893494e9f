#pragma once
// Keyframes the particles cannot reach. A sheet pinned in place holds each particle within its rest distance
// from every pin (its springs stretch only a little), so a target for a particle farther than that from a
// pin is out of reach, and so is a target for the particles' centroid farther from a pin than the farthest
// of them can be. Optimising towards such a target ends far from it however long it runs; `keyframe
// optimize` warns first. Each kind says where it places its particles (KeyframePlacement).
#include <string>
#include <vector>

#include "scene/scene.h"

namespace kf {

// Stretch allowed before a target counts as out of reach (10 % beyond the rest distance).
constexpr double kReachSlack = 1.1;

// One message per out-of-reach keyframe of a cloth scene with fixed pins (none for flocks, free sheets and
// capes, whose pins move): "FILE: /objectives/K: ..." naming the keyframe, the particle and the pin.
std::vector<std::string> unreachable_keyframes(const Scene& scene);

}  // namespace kf
