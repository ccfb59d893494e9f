#include "scene/flock_spec.h"

#include "scene/params.h"

namespace kf {

FlockSpec parse_flock_spec(Block& b) {
  FlockSpec s;
  s.agents = b.integer("agents", s.agents, 1, 1'000'000);
  s.mass = b.number("mass", s.mass, 1e-6, 1e6);
  b.finish();
  return s;
}

}  // namespace kf
