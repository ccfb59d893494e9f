#pragma once
// A rectangular cloth and its colliders as the scene file states them.
#include "core/types.h"

namespace kf {
class Block;

struct ClothSpec {
  int nx = 16, ny = 16;
};

ClothSpec parse_cloth_spec(Block& b);

}  // namespace kf
