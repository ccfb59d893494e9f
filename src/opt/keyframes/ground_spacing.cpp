#include "opt/keyframes/ground_spacing.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sim/flock/neighbor_grid.h"

namespace kf {

std::vector<double> nearest_neighbour_spacing(const VecX& x) {
  // Linear in the agents: each agent's nearest among those a grid finds within twice the mean spacing over
  // the flock's box; only agents with none that close are compared with all. Exact either way (the nearest
  // lies among the agents within any radius that holds one), and hypot does not see the sign of its inputs,
  // so every value is the one comparing all pairs gives.
  const int p = int(x.size() / 3);
  std::vector<double> nn(p, std::numeric_limits<double>::infinity());
  if (p < 2) return nn;
  double x0 = x[0], x1 = x[0], z0 = x[2], z1 = x[2];
  for (int i = 1; i < p; ++i) {
    x0 = std::min(x0, x[3 * i]), x1 = std::max(x1, x[3 * i]);
    z0 = std::min(z0, x[3 * i + 2]), z1 = std::max(z1, x[3 * i + 2]);
  }
  double radius = 2.0 * std::sqrt((x1 - x0) * (z1 - z0) / p);
  if (!(radius > 1e-9 && radius < 1e9)) radius = 1.0;  // coincident, collinear or non-finite positions
  auto distance = [&](int i, int j) { return std::hypot(x[3 * i] - x[3 * j], x[3 * i + 2] - x[3 * j + 2]); };
  NeighborGrid grid;
  grid.build(x, radius);
  for (int i = 0; i < p; ++i)
    for (int j : grid.neighbors(i)) nn[i] = std::min(nn[i], distance(i, j));
  for (int i = 0; i < p; ++i)
    if (grid.neighbors(i).empty())
      for (int j = 0; j < p; ++j)
        if (j != i) nn[i] = std::min(nn[i], distance(i, j));
  return nn;
}

std::vector<char> points_covered(const VecX& x, const std::vector<Vec2>& q, double radius) {
  // The points join the particles for one grid search a little wider than the radius; each pair found is
  // then tested exactly.
  const int p = int(x.size() / 3), s = int(q.size());
  std::vector<char> covered(s, 0);
  if (p == 0 || s == 0 || !(radius > 0)) return covered;
  VecX all = VecX::Zero(3 * (std::size_t(p) + s));
  all.head(3 * p) = x;
  for (int k = 0; k < s; ++k) all[3 * (p + k)] = q[k].x(), all[3 * (p + k) + 2] = q[k].y();
  NeighborGrid grid;
  grid.build(all, radius * (1 + 1e-9) + 1e-12);
  for (int k = 0; k < s; ++k)
    for (int i : grid.neighbors(p + k))
      if (i < p && Vec2(x[3 * i] - q[k].x(), x[3 * i + 2] - q[k].y()).squaredNorm() <= radius * radius) {
        covered[k] = 1;
        break;
      }
  return covered;
}

}  // namespace kf
