#include "core/ground_region.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"

namespace kf {

namespace {

// Toggles `inside` for each edge of the loop a ray from q toward +x crosses.
void cross_loop(const std::vector<Vec2>& loop, const Vec2& q, bool& inside) {
  for (size_t i = 0, j = loop.size() - 1; i < loop.size(); j = i++) {
    const Vec2 &a = loop[i], &b = loop[j];
    if ((a.y() > q.y()) != (b.y() > q.y()) && q.x() < (b.x() - a.x()) * (q.y() - a.y()) / (b.y() - a.y()) + a.x())
      inside = !inside;
  }
}

bool loop_contains(const std::vector<Vec2>& loop, const Vec2& q) {
  bool inside = false;
  cross_loop(loop, q, inside);
  return inside;
}

// Closest point of the loop's edges to q, if nearer than `best` (squared distance), which it updates.
void closest_on_loop(const std::vector<Vec2>& loop, const Vec2& q, double& best, Vec2& best_p) {
  for (size_t i = 0, j = loop.size() - 1; i < loop.size(); j = i++) {
    const Vec2 a = loop[j], e = loop[i] - loop[j];
    const double len2 = e.squaredNorm();
    const double t = len2 > 0 ? std::clamp((q - a).dot(e) / len2, 0.0, 1.0) : 0.0;
    const Vec2 p = a + t * e;
    const double d = (q - p).squaredNorm();
    if (d < best) {
      best = d;
      best_p = p;
    }
  }
}

double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// Whether segments ab and cd share a point (touching counts).
bool segments_meet(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const double d1 = cross2(b - a, c - a), d2 = cross2(b - a, d - a), d3 = cross2(d - c, a - c), d4 = cross2(d - c, b - c);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return true;
  auto on = [](const Vec2& p, const Vec2& q, const Vec2& r, double c) {  // r on segment pq, given collinear
    return c == 0 && r.x() >= std::min(p.x(), q.x()) && r.x() <= std::max(p.x(), q.x()) &&
           r.y() >= std::min(p.y(), q.y()) && r.y() <= std::max(p.y(), q.y());
  };
  return on(a, b, c, d1) || on(a, b, d, d2) || on(c, d, a, d3) || on(c, d, b, d4);
}

bool loops_meet(const std::vector<Vec2>& p, const std::vector<Vec2>& q) {
  for (size_t i = 0, j = p.size() - 1; i < p.size(); j = i++)
    for (size_t k = 0, l = q.size() - 1; k < q.size(); l = k++)
      if (segments_meet(p[j], p[i], q[l], q[k])) return true;
  return false;
}

}  // namespace

bool polygon_contains(const GroundRegion& region, const Vec2& q) {
  bool inside = false;  // even-odd rule
  cross_loop(region.outer, q, inside);
  for (const auto& hole : region.holes) cross_loop(hole, q, inside);
  return inside;
}

Vec2 closest_point_on_boundary(const GroundRegion& region, const Vec2& q) {
  double best = std::numeric_limits<double>::infinity();
  Vec2 best_p = q;
  closest_on_loop(region.outer, q, best, best_p);
  for (const auto& hole : region.holes) closest_on_loop(hole, q, best, best_p);
  return best_p;
}

Vec2 closest_point_in_polygon(const GroundRegion& region, const Vec2& q, bool* inside) {
  const bool in = polygon_contains(region, q);
  if (inside) *inside = in;
  if (in) return q;
  return closest_point_on_boundary(region, q);
}

namespace {

// The outer loop's bounding box and the grid of `spacing` region_samples lays over it. The cell counts are
// formed in double precision first: a shape of 1e9 m at a spacing of 1 mm overflows any integer.
struct SampleGrid {
  Vec2 lo, hi;
  double count = 1;  // nx * nz, however large
  int nx = 1, nz = 1;  // valid when !too_many()
  SampleGrid(const std::vector<Vec2>& polygon, double spacing) : lo(polygon.front()), hi(lo) {
    for (const Vec2& p : polygon) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    const double fx = std::max(1.0, std::round((hi.x() - lo.x()) / spacing));
    const double fz = std::max(1.0, std::round((hi.y() - lo.y()) / spacing));
    count = fx * fz;
    if (!too_many()) nx = int(fx), nz = int(fz);
  }
  bool too_many() const { return !(count <= kMaxRegionSamples); }
  static constexpr double kMaxRegionSamples = 1e5;
};

}  // namespace

double region_sample_count(const std::vector<Vec2>& outer, double spacing) {
  return SampleGrid(outer, spacing).count;
}

double sample_spacing_within_limit(const GroundRegion& region, double spacing) {
  while (SampleGrid(region.outer, spacing).too_many()) spacing *= 1.05;
  return spacing;
}

std::vector<Vec2> region_samples(const GroundRegion& region, double spacing) {
  const std::vector<Vec2>& polygon = region.outer;
  // Cell centres of a grid over the bounding box, so opposite sides are sampled alike.
  const SampleGrid grid(polygon, spacing);
  const Vec2 lo = grid.lo, hi = grid.hi;
  const int nx = grid.nx, nz = grid.nz;
  if (grid.too_many())
    throw InputError("shape keyframe: coverage spacing " + std::to_string(spacing) + " m gives more than 100,000 samples");
  const Vec2 start = 0.5 * (lo + hi) - 0.5 * spacing * Vec2(nx - 1, nz - 1);
  std::vector<Vec2> out;
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i) {
      const Vec2 q = start + spacing * Vec2(i, j);
      if (polygon_contains(region, q)) out.push_back(q);
    }
  return out;
}

std::string region_problem(const GroundRegion& region, const std::vector<std::string>& hole_names) {
  auto name_of = [&](size_t h) { return h < hole_names.size() ? hole_names[h] : "hole " + std::to_string(h); };
  for (size_t h = 0; h < region.holes.size(); ++h) {
    const auto& hole = region.holes[h];
    const std::string name = name_of(h);
    for (const Vec2& v : hole)
      if (!loop_contains(region.outer, v)) return name + " has a point outside the outer shape";
    if (loops_meet(hole, region.outer)) return name + " crosses the outer shape's edge";
    for (size_t o = 0; o < h; ++o) {
      const auto& other = region.holes[o];
      if (loops_meet(hole, other) || loop_contains(other, hole.front()) || loop_contains(hole, other.front()))
        return name + " overlaps " + name_of(o);
    }
  }
  return "";
}

}  // namespace kf
