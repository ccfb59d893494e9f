#include "report/shape_summary.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace kf {

namespace {

double polygon_area(const std::vector<Vec2>& p) {
  double twice = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    const Vec2& a = p[i];
    const Vec2& b = p[(i + 1) % p.size()];
    twice += a.x() * b.y() - b.x() * a.y();
  }
  return 0.5 * std::abs(twice);
}

}  // namespace

std::vector<ShapeSummary> shape_summaries(const Scene& scene) {
  std::vector<ShapeSummary> out;
  if (!scene.flock) return out;
  for (const ObjectiveSpec& o : scene.objectives) {
    const auto* shape = std::get_if<ShapeKeyframe>(&o.kind);
    if (!shape || shape->polygon.empty()) continue;
    ShapeSummary s;
    s.name = std::string(type_name(o)) + "@" + std::to_string(o.frame);
    s.x_min = s.x_max = shape->polygon.front().x();
    s.z_min = s.z_max = shape->polygon.front().y();
    for (const Vec2& q : shape->polygon) {
      s.x_min = std::min(s.x_min, q.x()), s.x_max = std::max(s.x_max, q.x());
      s.z_min = std::min(s.z_min, q.y()), s.z_max = std::max(s.z_max, q.y());
    }
    s.area = polygon_area(shape->polygon);
    for (const auto& hole : shape->holes) s.area -= polygon_area(hole);
    s.holes = int(shape->holes.size());
    s.spacing = scene.flock->avoidance.radius;
    // A hexagonal packing at spacing d gives each agent sqrt(3)/2 d² of the plane.
    s.holds = s.spacing > 0 ? int(std::floor(s.area / (0.5 * std::sqrt(3.0) * s.spacing * s.spacing))) : 0;
    s.agents = scene.flock->agents;
    out.push_back(s);
  }
  return out;
}

std::string shape_summary_line(const ShapeSummary& s) {
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "%s: x %.3g … %.3g m, z %.3g … %.3g m, area %.3g m², %d hole%s; holds %d agent%s %.3g m apart "
                "(the flock has %d)",
                s.name.c_str(), s.x_min, s.x_max, s.z_min, s.z_max, s.area, s.holes, s.holes == 1 ? "" : "s",
                s.holds, s.holds == 1 ? "" : "s", s.spacing, s.agents);
  return buf;
}

}  // namespace kf
