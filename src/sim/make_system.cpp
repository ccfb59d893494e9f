#include "sim/make_system.h"

#include "core/error.h"
#include "core/overloaded.h"

namespace kf {

std::unique_ptr<System> make_system(const Scene& scene, double h_override) {
  const double h = h_override > 0 ? h_override : scene.time.h();
  if (!scene.flock && !scene.cloth) throw InputError(scene.file.string() + ": /: the scene names no particle system");
  return visit_system(scene, Overloaded{
                                 [&](const FlockSpec&) { return make_flock_system(scene, h); },
                                 [&](const ClothSpec&) {
                                   return scene.character ? make_cape_system(scene, h) : make_cloth_system(scene, h);
                                 },
                             });
}

}  // namespace kf
