#pragma once
// Which particles a keyframe or a cloth's pins name, as a scene file says it, and targets relative to
// where the particles rest.
//
// A selector is a list of indices; a named set of a sheet ("all", "top_edge", "bottom_edge", "left_edge",
// "right_edge", "edges", "corners", "top_corners", "bottom_corners"); or, on a sheet, an object whose keys
// each narrow the set (all of them hold for every particle selected): "row": j, "column": i, "i": [i0, i1]
// and "j": [j0, j1] (inclusive ranges of the grid), "u": [u0, u1] and "v": [v0, v1] (a region of the rest
// sheet: metres along its width and height from particle (0, 0)). A selector that matches no particle is
// refused, naming it.
#include <string>
#include <vector>

#include "core/types.h"
#include "scene/cloth_spec.h"

namespace kf {
class Block;

// The named sets of a sheet, "all" first.
const std::vector<std::string>& named_particle_sets();

// The particles `key` of b selects, sorted and unique; `sheet` null for a flock (indices and "all" only).
// Empty means all particles. Throws InputError (via Block) naming the key.
std::vector<int> parse_particle_selector(Block& b, const std::string& key, int particles, const ClothSpec* sheet);

// Particle `index`'s position on the flat rest sheet (before its imperfection), metres.
Vec3 rest_position(const ClothSpec& sheet, int index);

}  // namespace kf
