#pragma once
// Each figure's own success measure, computed from the frames of a run (for report.json and tests).
#include <nlohmann/json.hpp>

#include "core/trajectory.h"
#include "scene/scene.h"

namespace kf {

// One JSON object per objective of the scene, in order, with "type", "frame" and its measures:
//  shape: inside_fraction, min_spacing, median_spacing (nearest-neighbour distances, metres);
//  center_of_mass: error, path_length, error_over_path;
//  position on one agent of a flock (the race): rank_at_start, rank_at_end along the heading
//    (0 = last, agents-1 = first), last_at_start, first_at_end;
//  position/velocity otherwise: rms_error;  arch: rms_distance, width, rms_over_width.
nlohmann::json figure_measures(const Scene& scene, const Trajectory& frames);

// Nearest-neighbour distance of each particle in the ground plane (x, z) at one state.
std::vector<double> nearest_neighbour_spacing(const VecX& x);

}  // namespace kf
