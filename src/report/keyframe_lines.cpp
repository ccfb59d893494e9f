#include "report/keyframe_lines.h"

#include "core/check.h"

namespace kf {

std::vector<std::string> keyframe_lines(const Scene& scene, const std::vector<KeyframeJudgement>& keyframes) {
  CHECK_EQ(keyframes.size(), scene.objectives.size());
  std::vector<std::string> out;
  for (size_t i = 0; i < keyframes.size(); ++i) {
    const KeyframeJudgement& k = keyframes[i];
    std::string line = k.name + ": " + k.error_after + k.error_phrase;
    if (k.judged) line += std::string(" (tolerance ") + k.tolerance + (k.met() ? ", met)" : ", not met)");
    else line += " (not judged)";
    out.push_back(std::move(line));
  }
  return out;
}

}  // namespace kf
