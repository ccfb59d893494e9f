#pragma once
// A seeded sub-millimetre imperfection of the initial sheet: every particle moved off the sheet's plane by
// an amount drawn uniformly from [-amplitude, amplitude]. The springs take their rest lengths from the
// moved sheet, so the imperfection is the sheet's own stress-free shape, not a force: a flat, symmetric
// start then no longer sits on a bifurcation (in-plane compression buckling, a sheet balanced on a
// sphere) whose side round-off picks.
#include <cstdint>

#include "core/types.h"

namespace kf {

// x: 3p positions of the flat sheet (metres), moved in place along normal (unit). amplitude: metres (0:
// nothing moves). The draws are the same on every platform and thread count for one seed.
void add_imperfection(VecX& x, const Vec3& normal, double amplitude, uint64_t seed);

}  // namespace kf
