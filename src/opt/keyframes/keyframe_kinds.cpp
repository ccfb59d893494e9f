// Every visit of a keyframe kind outside render/: each goes to the kind's own file through KeyframeKind<K>.
#include <algorithm>
#include <type_traits>
#include <variant>

#include "core/check.h"
#include "opt/keyframes/keyframe_kind.h"

namespace kf {

std::unique_ptr<ObjectiveTerm> make_objective_term(const ObjectiveSpec& s, int particles) {
  return std::visit([&](const auto& k) { return KeyframeKind<std::decay_t<decltype(k)>>::term(s, k, particles); },
                    s.kind);
}

std::vector<KeyframeMeasure> measure_keyframes(const Scene& scene, const Trajectory& t) {
  CHECK_GT(t.frames(), 0);
  CHECK_EQ(t.particles, scene.particles());
  std::vector<KeyframeMeasure> out;
  for (const ObjectiveSpec& o : scene.objectives) {
    const KeyframeRun run{scene, t, std::min(o.frame, t.frames() - 1)};
    out.push_back(std::visit(
        [&](const auto& k) { return KeyframeKind<std::decay_t<decltype(k)>>::measure(run, o, k); }, o.kind));
  }
  return out;
}

KeyframePlacement keyframe_placement(const ObjectiveSpec& s) {
  return std::visit([&](const auto& k) { return KeyframeKind<std::decay_t<decltype(k)>>::placement(s, k); },
                    s.kind);
}

}  // namespace kf
