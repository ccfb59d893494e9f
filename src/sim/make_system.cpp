#include "sim/make_system.h"

#include "core/error.h"

namespace kf {

std::unique_ptr<System> make_system(const Scene& scene, double h_override) {
  const double h = h_override > 0 ? h_override : scene.time.h();
  if (scene.flock) return make_flock_system(scene, h);
  if (scene.character) return make_cape_system(scene, h);
  if (scene.cloth) return make_cloth_system(scene, h);
  throw InputError(scene.file.string() + ": /: the scene names no particle system");
}

}  // namespace kf
