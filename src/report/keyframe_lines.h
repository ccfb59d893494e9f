#pragma once
// What a run's keyframes read as, one line each, for the terminal ("center_of_mass@20: 20.60 cm from its
// target (tolerance 1.00 cm, not met)").
#include <string>
#include <vector>

#include "opt/diagnosis.h"
#include "scene/scene.h"

namespace kf {

// One line per judgement, keyframes[i] judging scene.objectives[i]; the error after (the run's own).
std::vector<std::string> keyframe_lines(const Scene& scene, const std::vector<KeyframeJudgement>& keyframes);

}  // namespace kf
