#include "scene/render_spec.h"

#include "scene/params.h"

namespace kf {

RenderSpec parse_render_spec(Block& b) {
  RenderSpec s;
  s.width = b.integer("width", s.width, 16, 8192);
  s.height = b.integer("height", s.height, 16, 8192);
  b.finish();
  return s;
}

}  // namespace kf
