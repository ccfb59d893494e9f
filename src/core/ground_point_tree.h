#pragma once
// Nearest-point and within-radius queries over points on the ground plane (x, z), by a k-d tree.
//
// A query costs O(log n + points found) for any layout of the points: dense, sparse, clustered, or far from
// the query (where a uniform grid would scan every empty cell in between). Squared distances are computed as
// (x_i - q_x)^2 + (z_i - q_z)^2, the way a loop over all points computes them, and a subtree is skipped only
// when its splitting line alone puts it beyond the bound, so every answer is the one comparing all points
// gives, to the bit. After the first build with a given n nothing is allocated, except that a query's output
// list grows (amortised) when it finds more points than ever before.
#include <vector>

#include "core/types.h"

namespace kf {

class GroundPointTree {
 public:
  // x: 3p stacked positions (m; y ignored); ids: the particles to hold (their positions must be finite).
  // A point's index in the queries below is its position in ids.
  void build(const VecX& x, const std::vector<int>& ids);
  // min over points of the squared distance to q (m^2); +inf when there are none. The search stops as soon as
  // a point within `enough` is found (and returns that point's squared distance, <= enough): pass -1 for the
  // exact minimum.
  double nearest_squared(const Vec2& q, double enough = -1) const;
  struct Found {
    int index;       // in ids
    double squared;  // distance to q, m^2
  };
  // The points with squared distance to q <= r2, in increasing order of index, into out (cleared first).
  void within(const Vec2& q, double r2, std::vector<Found>& out) const;

 private:
  static constexpr int kLeaf = 8;  // ranges of at most this many points are scanned, not split
  struct Point {
    double x, z;
    int index;  // in ids
    int axis;   // of the split at this slot (0: x, 1: z), when it splits
  };
  // The subtree over slots [lo, hi): split at mid = (lo + hi) / 2 on point mid's axis; slots before mid have
  // that coordinate <= the mid point's, slots after >=.
  void build(int lo, int hi);
  void nearest(int lo, int hi, const Vec2& q, double enough, double& best) const;
  void within(int lo, int hi, const Vec2& q, double r2, std::vector<Found>& out) const;
  double squared(int s, const Vec2& q) const {
    const double dx = points_[s].x - q.x(), dz = points_[s].z - q.y();
    return dx * dx + dz * dz;
  }

  std::vector<Point> points_;  // in tree order
};

}  // namespace kf
