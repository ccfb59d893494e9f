#include "opt/friction_continuation.h"

namespace kf {

bool has_friction(const Scene& scene) {
  if (!scene.cloth) return false;
  for (const auto& c : scene.cloth->colliders)
    if (c.friction > 0) return true;
  if (scene.cloth->self.enabled && scene.cloth->self.friction > 0) return true;
  return scene.character && (scene.character->body_friction > 0 || scene.character->self_friction > 0);
}

Scene with_friction_scaled(const Scene& scene, double scale) {
  Scene out = scene;
  if (!out.cloth) return out;
  for (auto& c : out.cloth->colliders) c.friction *= scale;
  out.cloth->self.friction *= scale;
  if (out.character) {
    out.character->body_friction *= scale;
    out.character->self_friction *= scale;
  }
  return out;
}

}  // namespace kf
