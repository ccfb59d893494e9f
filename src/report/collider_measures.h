#pragma once
// A cloth's own measures over a run, beside its keyframes' (report.json's "measures"): its colliders' and,
// for a free sheet, how far it turned over.
#include <nlohmann/json.hpp>

#include "core/trajectory.h"
#include "scene/scene.h"

namespace kf {

// Appends to `out`, for a cloth without pins or mesh, one "sheet" object: flip_degrees (the largest angle
// between the sheet's normal, from its corner diagonals, and its normal at frame 0, over all frames) and
// flip_degrees_at_end; then one object per collider that has measures ("collider": its index):
//  torus ("type": "ring") over all frames: through_ring (the centre of mass crosses the ring's plane inside
//   the tube's inner circle), crossings (plane crossings of the centre of mass),
//   min_distance_to_ring_axis_when_crossing (metres, null without a crossing), inner_radius (metres),
//   min_signed_distance (to the torus surface over all particles and frames, metres; negative is
//   penetration), min_signed_distance_between_frames (also along each particle's straight path from one
//   frame to the next, sampled at a quarter of the tube radius), penetration_free (both >= 0),
//   end_beyond_ring_plane (the last frame's centre of mass along the axis from the ring's plane, positive on
//   the side away from the start, metres);
//  ground, for a cloth without pins ("type": "ground"): lowest_at_end, mean_height_at_end (particles above
//   the plane at the last frame, metres), on_ground_at_end (lowest within two contact thicknesses);
//  box and rectangle: surface_measures below.
void add_cloth_measures(const ClothSpec& cloth, const Trajectory& frames, nlohmann::json& out);

nlohmann::json ring_measures(const TorusShape& torus, const Trajectory& frames);
nlohmann::json ground_measures(const GroundShape& ground, double thickness, const Trajectory& frames);
// A box's or a rectangle's: the smallest signed distance of any particle from its surface over the frames
// ("min_distance", m, negative: inside; "min_distance_frame") and how many particles rest on it at the end
// (within two contact thicknesses: "touching_at_end").
nlohmann::json surface_measures(const ColliderSpec& collider, const Trajectory& frames);

}  // namespace kf
