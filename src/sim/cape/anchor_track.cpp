#include "sim/cape/anchor_track.h"

#include <algorithm>

namespace kf {

std::vector<Vec3> polyline_points(const std::vector<Vec3>& pts, const std::vector<double>& params) {
  std::vector<double> cum(pts.size(), 0.0);
  for (size_t k = 1; k < pts.size(); ++k) cum[k] = cum[k - 1] + (pts[k] - pts[k - 1]).norm();
  std::vector<Vec3> out;
  out.reserve(params.size());
  for (double s : params) {
    const double target = std::clamp(s, 0.0, 1.0) * cum.back();
    size_t k = 1;
    while (k + 1 < pts.size() && cum[k] < target) ++k;
    if (pts.size() == 1 || cum[k] == cum[k - 1]) {
      out.push_back(pts[std::min(k, pts.size() - 1)]);
      continue;
    }
    const double a = (target - cum[k - 1]) / (cum[k] - cum[k - 1]);
    out.push_back((1 - a) * pts[k - 1] + a * pts[k]);
  }
  return out;
}

AnchorTrack::AnchorTrack(const std::vector<std::vector<Vec3>>& anchors, const std::vector<int>& pinned,
                         const std::vector<double>& params, int particles, double h)
    : slot_(particles, -1), h_(h) {
  for (size_t s = 0; s < pinned.size(); ++s) slot_[pinned[s]] = int(s);
  table_.reserve(anchors.size());
  for (const auto& a : anchors) table_.push_back(polyline_points(a, params));
}

void AnchorTrack::state(int n, int particle, const Vec3& x0, Vec3& position, Vec3& velocity) const {
  const int s = slot_[particle];
  if (s < 0) {
    position = x0;
    velocity.setZero();
    return;
  }
  const int last = steps();
  const int a = std::clamp(n, 0, last), b = std::clamp(n + 1, 0, last);
  position = table_[a][s];
  velocity = (table_[b][s] - table_[a][s]) / h_;
}

}  // namespace kf
