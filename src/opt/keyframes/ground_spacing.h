#pragma once
// Distances between particles in the ground plane (x, z), for the shape keyframe's measures.
#include <vector>

#include "core/types.h"

namespace kf {

// Nearest-neighbour distance of each particle in the ground plane (x, z) at one state.
// Linear in the particles (a neighbour grid), equal to comparing all pairs.
std::vector<double> nearest_neighbour_spacing(const VecX& x);

// Whether each ground point q_k = (x, z) has a particle within `radius` (|x_i - q_k|^2 <= radius^2 in the
// ground plane): the coverage measure. Linear in particles and points, equal to testing all of them.
std::vector<char> points_covered(const VecX& x, const std::vector<Vec2>& q, double radius);

}  // namespace kf
