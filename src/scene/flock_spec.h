#pragma once
// A flock of agents on the ground plane (y = 0) as the scene file states it.
#include "core/types.h"

namespace kf {
class Block;

struct FlockSpec {
  int agents = 200;
  double mass = 1.0;
};

FlockSpec parse_flock_spec(Block& b);

}  // namespace kf
