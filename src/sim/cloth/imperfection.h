#pragma once
// A seeded sub-millimetre imperfection of the initial sheet: every free particle moved off the sheet's plane
// by an amount drawn uniformly from [-amplitude, amplitude]; pinned ones stay where the scene puts them. The
// springs take their rest lengths from the moved sheet, so the imperfection is the sheet's own stress-free
// shape, not a force: a flat, symmetric start then no longer sits on a bifurcation (in-plane compression
// buckling, a sheet balanced on a sphere) whose side round-off picks.
#include <cstdint>
#include <vector>

#include "core/types.h"

namespace kf {

// x: 3p positions of the flat sheet (metres), moved in place along normal (unit), except the particles in
// `pinned`. amplitude: metres (0: nothing moves). The draws are the same on every platform and thread count
// for one seed, and each particle's draw is the same whichever others are pinned.
void add_imperfection(VecX& x, const Vec3& normal, double amplitude, uint64_t seed, const std::vector<int>& pinned);

}  // namespace kf
