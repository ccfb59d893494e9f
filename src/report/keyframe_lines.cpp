#include "report/keyframe_lines.h"

#include "core/check.h"
#include "core/overloaded.h"

namespace kf {

namespace {

// How an error of this keyframe's kind reads after its value.
const char* error_phrase(const ObjectiveKind& kind) {
  return std::visit(Overloaded{
                        [](const PositionKeyframe&) { return " from its targets (RMS)"; },
                        [](const VelocityKeyframe&) { return " from its target velocities (RMS)"; },
                        [](const CenterOfMassKeyframe&) { return " from its target"; },
                        [](const ShapeKeyframe&) { return ""; },
                        [](const ArchKeyframe&) { return " from the arch's cylinder (RMS)"; },
                    },
                    kind);
}

}  // namespace

std::vector<std::string> keyframe_lines(const Scene& scene, const std::vector<KeyframeJudgement>& keyframes) {
  CHECK_EQ(keyframes.size(), scene.objectives.size());
  std::vector<std::string> out;
  for (size_t i = 0; i < keyframes.size(); ++i) {
    const KeyframeJudgement& k = keyframes[i];
    std::string line = k.name + ": " + k.error_after + error_phrase(scene.objectives[i].kind);
    if (k.judged) line += std::string(" (tolerance ") + k.tolerance + (k.met() ? ", met)" : ", not met)");
    else line += " (not judged)";
    out.push_back(std::move(line));
  }
  return out;
}

}  // namespace kf
