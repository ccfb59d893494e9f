#include "core/ground_point_tree.h"

#include <algorithm>
#include <limits>
#include <tuple>

namespace kf {

void GroundPointTree::build(const VecX& x, const std::vector<int>& ids) {
  const int n = int(ids.size());
  points_.resize(n);
  for (int k = 0; k < n; ++k) points_[k] = {x[3 * ids[k]], x[3 * ids[k] + 2], k, 0};
  build(0, n);
}

void GroundPointTree::build(int lo, int hi) {
  if (hi - lo <= kLeaf) return;
  // Split across the wider extent, at the median; ties in the coordinate are ordered by index, so the tree
  // depends only on the points.
  double x0 = points_[lo].x, x1 = x0, z0 = points_[lo].z, z1 = z0;
  for (int s = lo + 1; s < hi; ++s) {
    x0 = std::min(x0, points_[s].x), x1 = std::max(x1, points_[s].x);
    z0 = std::min(z0, points_[s].z), z1 = std::max(z1, points_[s].z);
  }
  const int axis = (z1 - z0) > (x1 - x0) ? 1 : 0, mid = (lo + hi) / 2;
  std::nth_element(points_.begin() + lo, points_.begin() + mid, points_.begin() + hi,
                   [axis](const Point& a, const Point& b) {
                     return axis ? std::tie(a.z, a.index) < std::tie(b.z, b.index)
                                 : std::tie(a.x, a.index) < std::tie(b.x, b.index);
                   });
  points_[mid].axis = axis;
  build(lo, mid);
  build(mid + 1, hi);
}

double GroundPointTree::nearest_squared(const Vec2& q, double enough) const {
  double best = std::numeric_limits<double>::infinity();
  nearest(0, int(points_.size()), q, enough, best);
  return best;
}

void GroundPointTree::nearest(int lo, int hi, const Vec2& q, double enough, double& best) const {
  if (best <= enough) return;
  if (hi - lo <= kLeaf) {
    for (int s = lo; s < hi; ++s) best = std::min(best, squared(s, q));
    return;
  }
  const int mid = (lo + hi) / 2;
  const Point& m = points_[mid];
  // Every point on the far side of the splitting line is at least |diff| away along the axis, and rounding
  // is monotone, so a far side with diff^2 >= best holds no point nearer than best.
  const double diff = m.axis ? q.y() - m.z : q.x() - m.x;
  best = std::min(best, squared(mid, q));
  if (diff < 0) {
    nearest(lo, mid, q, enough, best);
    if (diff * diff < best) nearest(mid + 1, hi, q, enough, best);
  } else {
    nearest(mid + 1, hi, q, enough, best);
    if (diff * diff < best) nearest(lo, mid, q, enough, best);
  }
}

void GroundPointTree::within(const Vec2& q, double r2, std::vector<Found>& out) const {
  out.clear();
  within(0, int(points_.size()), q, r2, out);
  std::sort(out.begin(), out.end(), [](const Found& a, const Found& b) { return a.index < b.index; });
}

void GroundPointTree::within(int lo, int hi, const Vec2& q, double r2, std::vector<Found>& out) const {
  auto take = [&](int s) {
    const double d2 = squared(s, q);
    if (d2 <= r2) out.push_back({points_[s].index, d2});
  };
  if (hi - lo <= kLeaf) {
    for (int s = lo; s < hi; ++s) take(s);
    return;
  }
  const int mid = (lo + hi) / 2;
  const Point& m = points_[mid];
  const double diff = m.axis ? q.y() - m.z : q.x() - m.x;
  take(mid);
  // The near side always; the far side only when the splitting line is within the radius.
  if (diff <= 0 || diff * diff <= r2) within(lo, mid, q, r2, out);
  if (diff >= 0 || diff * diff <= r2) within(mid + 1, hi, q, r2, out);
}

}  // namespace kf
