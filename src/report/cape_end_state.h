#pragma once
// How a cape blend ended, beside the uncontrolled run.
#include <nlohmann/json.hpp>

#include "core/trajectory.h"
#include "scene/scene.h"

namespace kf {

// The cape blend's end state (scenes with a character and an end target): for the run and for the
// uncontrolled run beside it, rms_position_error (m), rms_position_error_percent (of the cape length),
// rms_velocity_error (m/s), at the frame of the end target; plus cape_length and frame. Null without an
// end target.
nlohmann::json cape_end_state(const Scene& scene, const Trajectory& run, const Trajectory& uncontrolled);

}  // namespace kf
