#pragma once
// Camera, lights and look of a scene's renders as the scene file states them.
#include "core/types.h"

namespace kf {
class Block;

struct RenderSpec {
  int width = 640, height = 480;
};

RenderSpec parse_render_spec(Block& b);

}  // namespace kf
