#pragma once
// Each figure's own success measure, computed from the frames of a run (for report.json and tests).
#include <vector>

#include <nlohmann/json.hpp>

#include "core/trajectory.h"
#include "opt/keyframes/keyframe_kind.h"
#include "scene/scene.h"

namespace kf {

// One JSON object per objective of the scene, in order, with "type", "frame" and its kind's measures (each
// kind's file in opt/keyframes/ lists them), then the system's own (a cloth's: report/collider_measures.h).
nlohmann::json figure_measures(const Scene& scene, const Trajectory& frames);
// The same from the keyframes' measures already taken (measure_keyframes(scene, frames)).
nlohmann::json figure_measures(const Scene& scene, const Trajectory& frames,
                               const std::vector<KeyframeMeasure>& keyframes);

}  // namespace kf
