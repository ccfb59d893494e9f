#include "opt/keyframes/keyframe_reach.h"

#include <algorithm>
#include <cstdio>

#include "opt/keyframes/keyframe_kind.h"
#include "scene/cloth_mesh_spec.h"

namespace kf {
namespace {

Vec3 layout_position(const ClothSpec& c, int particle) { return cloth_rest_position(c, particle); }

// A pinned particle's own target this close to it (metres) is where the pin holds it: targets are written
// rounded (to a tenth of a millimetre, say).
constexpr double kPinnedTargetSlack = 1e-3;

// The pin that most limits a particle at rest position `rest` from reaching `target`: the largest ratio of
// the target's distance from the pin to the particle's rest distance from it (-1 when no pin limits it).
struct Limit {
  double ratio = 0, distance = 0, reach = 0;
  int pin = -1;
};
Limit worst_pin(const ClothSpec& c, const Vec3& rest, const Vec3& target) {
  Limit w;
  for (int p : c.pins) {
    const Vec3 pin = layout_position(c, p);
    const double reach = (rest - pin).norm(), distance = (target - pin).norm();
    const double ratio = reach > 0 ? distance / reach : (distance > kPinnedTargetSlack ? 1e30 : 0.0);
    if (ratio > w.ratio) w = {ratio, distance, reach, p};
  }
  return w;
}

}  // namespace

std::vector<std::string> unreachable_keyframes(const Scene& scene) {
  std::vector<std::string> out;
  if (!scene.cloth || scene.character || scene.cloth->pins.empty()) return out;
  const ClothSpec& c = *scene.cloth;
  const int p = scene.particles();
  int index = 0;
  for (const ObjectiveSpec& o : scene.objectives) {
    const int k = index++;
    if (o.source != ObjectiveSource::kScene) continue;
    auto particle = [&](size_t i) { return o.particles.empty() ? int(i) : o.particles[i]; };
    const size_t n = o.particles.empty() ? size_t(p) : o.particles.size();
    const KeyframePlacement place = keyframe_placement(o);
    char msg[512] = "";
    switch (place.kind) {
      case KeyframePlacement::Kind::kNone:
        break;
      case KeyframePlacement::Kind::kParticles:
        for (size_t i = 0; i < n && !msg[0]; ++i) {
          const Vec3& t = place.targets.size() == 1 ? place.targets[0] : place.targets[i];
          const Limit w = worst_pin(c, layout_position(c, particle(i)), t);
          if (w.ratio > kReachSlack)
            std::snprintf(msg, sizeof msg,
                          "particle %d's target at frame %d is %.3f m from pin %d, which holds it within "
                          "%.3f m (its rest distance): out of reach",
                          particle(i), o.frame, w.distance, w.pin, w.reach);
        }
        break;
      case KeyframePlacement::Kind::kCentroid:
        for (int pin : c.pins) {
          const Vec3 at = layout_position(c, pin);
          double reach = 0;
          for (size_t i = 0; i < n; ++i) reach = std::max(reach, (layout_position(c, particle(i)) - at).norm());
          const double distance = (place.targets[0] - at).norm();
          if (distance > kReachSlack * reach) {
            std::snprintf(msg, sizeof msg,
                          "the centre-of-mass target at frame %d is %.3f m from pin %d, whose particles "
                          "here are at most %.3f m from it: out of reach",
                          o.frame, distance, pin, reach);
            break;
          }
        }
        break;
    }
    if (msg[0])
      out.push_back(scene.file.string() + ": /objectives/" + std::to_string(k) + ": " + msg +
                    " (the sheet stretches little; move the target or the pins)");
  }
  return out;
}

}  // namespace kf
