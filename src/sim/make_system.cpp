#include "sim/make_system.h"

#include "core/error.h"
#include "core/overloaded.h"
#include "sim/cape/cape_system.h"
#include "sim/cloth/cloth_system.h"

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

ClothSystem* cloth_of(System& sys) {
  if (auto* cloth = dynamic_cast<ClothSystem*>(&sys)) return cloth;
  if (auto* cape = dynamic_cast<CapeSystem*>(&sys)) return &cape->cloth();
  return nullptr;
}

}  // namespace kf
