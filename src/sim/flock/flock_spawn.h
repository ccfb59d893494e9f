#pragma once
// Initial placement of a flock: a jittered square lattice filling the spawn disc.
#include "core/types.h"
#include "scene/flock_spec.h"

namespace kf {

// Positions (3p, m, y = 0) of spec.agents agents inside the disc spec.spawn (centre, radius), no two
// closer than spec.min_spawn_distance(). The lattice is as coarse as the disc allows and each point is
// jittered by a seeded offset of at most half the slack, so the minimum distance holds by construction.
// Same seed, same positions. Throws std::invalid_argument when the disc cannot hold the agents (the parser
// refuses such a scene first, with the field named).
VecX spawn_positions(const FlockSpec& spec, unsigned seed);

}  // namespace kf
