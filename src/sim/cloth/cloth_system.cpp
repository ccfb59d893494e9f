#include "core/error.h"
#include "sim/make_system.h"

namespace kf {
std::unique_ptr<System> make_cloth_system(const Scene& scene, double) {
  throw std::runtime_error("cloth simulation is not available yet");
}
}  // namespace kf
