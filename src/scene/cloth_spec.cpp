#include "scene/cloth_spec.h"

#include "scene/params.h"

namespace kf {

ClothSpec parse_cloth_spec(Block& b) {
  ClothSpec s;
  s.nx = b.integer("nx", s.nx, 2, 1024);
  s.ny = b.integer("ny", s.ny, 2, 1024);
  b.finish();
  return s;
}

}  // namespace kf
