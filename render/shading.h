#pragma once
// The lighting both back ends draw with (raster/ in GLSL, rt/ in C++): a sun along look.light_direction
// and a sky brighter overhead,
//   colour = albedo * (ambient * sky_light(n) + sun(n)) * norm_k,   sun(n) = max(n . light, 0)
// (rt/ also shadows the sun and occludes the sky). norm_k keeps a lit surface facing the ground plane's
// normal near its albedo however high the sun stands.
#include <algorithm>

#include "render/geometry/frame_geometry.h"
#include "scene/render_spec.h"

namespace kf::render {

// Sky light on a surface with unit normal n (n_y = ny): brightest facing up.
inline float sky_light(float ny) { return 0.75f + 0.25f * ny; }
// The same in GLSL, put in front of the raster back end's fragment shader.
constexpr const char* kSkyLightGlsl = "float sky_light(float ny) { return 0.75 + 0.25 * ny; }\n";

struct Lighting {
  float ambient;       // strength of the sky light (look.ambient)
  float norm_k;        // 1 / (ambient + the sun's height over the ground plane, at least 0.2)
  float shadow_alpha;  // the sun's share of the light: how dark a full shadow is
};

inline Lighting lighting(const RenderSpec& look, const GroundPlane& plane) {
  const double up_sun = std::max(look.light_direction.dot(plane.normal), 0.2);
  return {float(look.ambient), float(1.0 / (look.ambient + up_sun)), float(up_sun / (look.ambient + up_sun))};
}

}  // namespace kf::render
