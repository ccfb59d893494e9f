#include "render/geometry/height_target.h"

#include <algorithm>
#include <limits>

#include "core/check.h"

namespace kf::render {

std::vector<Vec3> height_target_outline(const ObjectiveSpec& o, const HeightKeyframe& k, const VecX& x,
                                        int particles, double pad) {
  CHECK_EQ(x.size(), 3 * particles);
  double lo_x = std::numeric_limits<double>::infinity(), hi_x = -lo_x, lo_z = lo_x, hi_z = -lo_x;
  const auto add = [&](int i) {
    CHECK(i >= 0 && i < particles);
    lo_x = std::min(lo_x, x[3 * i]), hi_x = std::max(hi_x, x[3 * i]);
    lo_z = std::min(lo_z, x[3 * i + 2]), hi_z = std::max(hi_z, x[3 * i + 2]);
  };
  if (o.particles.empty())
    for (int i = 0; i < particles; ++i) add(i);
  for (int i : o.particles) add(i);
  if (!(lo_x <= hi_x)) return {};  // no particles
  lo_x -= pad, hi_x += pad, lo_z -= pad, hi_z += pad;
  const double h = k.height;
  return {Vec3(lo_x, h, lo_z), Vec3(hi_x, h, lo_z), Vec3(hi_x, h, hi_z), Vec3(lo_x, h, hi_z)};
}

}  // namespace kf::render
