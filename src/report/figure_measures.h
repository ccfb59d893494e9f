#pragma once
// Each figure's own success measure, computed from the frames of a run (for report.json and tests).
#include <nlohmann/json.hpp>

#include "core/trajectory.h"
#include "scene/scene.h"

namespace kf {

// One JSON object per objective of the scene, in order, with "type", "frame" and its measures:
//  shape: inside_fraction, coverage_fraction, coverage_radius, min_spacing, median_spacing (nearest-neighbour
//    distances, metres);
//  center_of_mass: error, path_length, error_over_path;
//  position on one agent of a flock (the race): rank_at_start, rank_at_end along the heading
//    (0 = last, agents-1 = first), last_at_start, first_at_end, racer_rank (1 = first), racer_lead,
//    racer_within_front, flock_groups_max, flock_connected;
//  position/velocity otherwise: rms_error (metres, m/s; cloth also rms_over_width: over the sheet's width
//    at frame 0);  arch: rms_distance, width, rms_over_width.
// Then, for a cloth, one object per torus collider ("type": "ring", "collider": its index) over all frames:
//  through_ring (the centre of mass crosses the ring's plane inside the tube's inner circle),
//  crossings (plane crossings of the centre of mass), min_distance_to_ring_axis_when_crossing (metres, null
//  without a crossing), inner_radius (metres), min_signed_distance (to the torus surface over all particles
//  and frames, metres; negative is penetration), min_signed_distance_between_frames (also along each
//  particle's straight path from one frame to the next, sampled at a quarter of the tube radius),
//  penetration_free (both >= 0), end_beyond_ring_plane (the last frame's centre of mass along the axis from
//  the ring's plane, positive on the side away from the start, metres). For a cloth without pins, one
//  object per ground collider ("type": "ground", "collider"): lowest_at_end, mean_height_at_end (particles
//  above the plane at the last frame, metres), on_ground_at_end (lowest within two contact thicknesses).
//  And one "sheet" object for a cloth without pins: flip_degrees (the largest angle between
//  the sheet's normal, from its corner diagonals, and its normal at frame 0, over all frames) and
//  flip_degrees_at_end.
nlohmann::json figure_measures(const Scene& scene, const Trajectory& frames);

// The cape blend's end state (scenes with a character and an end target): for the run and for the
// uncontrolled run beside it, rms_position_error (m), rms_position_error_percent (of the cape length),
// rms_velocity_error (m/s), at the frame of the end target; plus cape_length and frame. Null without an
// end target.
nlohmann::json cape_end_state(const Scene& scene, const Trajectory& run, const Trajectory& uncontrolled);

// Ring measures of one torus collider over the frames of a run (the "ring" object described above).
nlohmann::json ring_measures(const TorusShape& torus, const Trajectory& frames);
nlohmann::json ground_measures(const GroundShape& ground, double thickness, const Trajectory& frames);
// A box's or a rectangle's: the smallest signed distance of any particle from its surface over the frames
// ("min_distance", m, negative: inside; "min_distance_frame") and how many particles rest on it at the end
// (within two contact thicknesses: "touching_at_end").
nlohmann::json surface_measures(const ColliderSpec& collider, const Trajectory& frames);

// Nearest-neighbour distance of each particle in the ground plane (x, z) at one state.
// Linear in the particles (a neighbour grid), equal to comparing all pairs.
std::vector<double> nearest_neighbour_spacing(const VecX& x);

// Whether each ground point q_k = (x, z) has a particle within `radius` (|x_i - q_k|^2 <= radius^2 in the
// ground plane): the coverage measure. Linear in particles and points, equal to testing all of them.
std::vector<char> points_covered(const VecX& x, const std::vector<Vec2>& q, double radius);

}  // namespace kf
