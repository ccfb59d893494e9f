#pragma once
// A region on the ground: an outer polygon with polygonal holes, in (x, z), metres. Seen from above (as
// `keyframe render --view top` shows it) x runs to the right and z toward the viewer.
#include <string>
#include <utility>
#include <vector>

#include "core/types.h"

namespace kf {

struct GroundRegion {
  std::vector<Vec2> outer;               // closed polygon (last point joins the first), either orientation
  std::vector<std::vector<Vec2>> holes;  // closed polygons inside `outer`, not overlapping: left out of the region
  GroundRegion(std::vector<Vec2> outer_loop = {}, std::vector<std::vector<Vec2>> hole_loops = {})
      : outer(std::move(outer_loop)), holes(std::move(hole_loops)) {}
};

// Inside the outer loop and inside no hole (the even-odd rule over every loop's edges).
bool polygon_contains(const GroundRegion& region, const Vec2& q);
// Closest point of the region's boundary (the edges of every loop, holes included) to q, inside or out.
Vec2 closest_point_on_boundary(const GroundRegion& region, const Vec2& q);
// Closest point of the closed region to q; q itself when q is inside.
Vec2 closest_point_in_polygon(const GroundRegion& region, const Vec2& q, bool* inside = nullptr);
// The points of a square grid of `spacing` (cell centres, centred in the outer loop's bounding box) inside the
// region: where a shape keyframe asks for an agent nearby. Throws InputError past 100,000 points.
std::vector<Vec2> region_samples(const GroundRegion& region, double spacing);
// How many cells that grid has (inside the region or not), in double precision: checked when a scene is read.
double region_sample_count(const std::vector<Vec2>& outer, double spacing);
// `spacing`, or the least coarser one (in 5 % steps) at which region_samples stays within its 100,000 points:
// for measuring a region far larger than its spacing was chosen for (a crowd's shape).
double sample_spacing_within_limit(const GroundRegion& region, double spacing);

// Why the loops are not an outer polygon with holes, as "hole K ..." (a vertex outside the outer loop or
// inside another hole, edges of two loops crossing); empty when they are. `hole_names` (optional) replaces
// "hole K" in the message.
std::string region_problem(const GroundRegion& region, const std::vector<std::string>& hole_names = {});

}  // namespace kf
