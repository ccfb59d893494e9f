// The ground-plane k-d tree against comparing every point: the same nearest squared distance and the same
// points within a radius, bit for bit, over uniform, clustered (with coincident points), collinear and far
// layouts, and queries inside, beside and far from the points.
#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "core/ground_point_tree.h"

namespace kf {
namespace {

double squared(const VecX& x, int i, const Vec2& q) {
  const double dx = x[3 * i] - q.x(), dz = x[3 * i + 2] - q.y();
  return dx * dx + dz * dz;
}

// Positions of n points: uniform over a square, a tight clump with duplicates and far strays, or on a line.
VecX layout(const std::string& kind, int n, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-10, 10);
  std::normal_distribution<double> clump(0, 0.05);
  VecX x = VecX::Zero(3 * n);
  for (int i = 0; i < n; ++i) {
    if (kind == "uniform") x[3 * i] = u(rng), x[3 * i + 2] = u(rng);
    if (kind == "clustered") {
      x[3 * i] = 4 + clump(rng), x[3 * i + 2] = -3 + clump(rng);
      if (i % 7 == 0 && i > 0) x[3 * i] = x[3 * (i - 1)], x[3 * i + 2] = x[3 * (i - 1) + 2];  // coincident
      if (i % 97 == 0) x[3 * i] = 40 * u(rng), x[3 * i + 2] = 40 * u(rng);                 // strays
    }
    if (kind == "line") x[3 * i] = u(rng), x[3 * i + 2] = 2.0;
  }
  return x;
}

TEST(GroundPointTree, NearestAndWithinEqualComparingEveryPoint) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> uq(-30, 30);
  for (const std::string kind : {"uniform", "clustered", "line"})
    for (int n : {1, 5, 9, 300, 2000}) {
      const VecX x = layout(kind, n, rng);
      std::vector<int> ids;  // every other point and some of the rest, so indices in ids differ from particles
      for (int i = 0; i < n; ++i)
        if (i % 2 == 0 || i % 3 == 0) ids.push_back(i);
      if (ids.empty()) continue;
      GroundPointTree tree;
      tree.build(x, ids);
      std::vector<GroundPointTree::Found> found;
      int nonempty = 0;
      for (int t = 0; t < 200; ++t) {
        // Queries on points (distance 0), near them and anywhere, out to far beyond the layout.
        const Vec2 q = t % 4 == 0 ? Vec2(x[3 * ids[t % ids.size()]], x[3 * ids[t % ids.size()] + 2])
                                  : Vec2(uq(rng) * (t % 3 == 0 ? 0.2 : 1.0), uq(rng));
        double best = std::numeric_limits<double>::infinity();
        for (int i : ids) best = std::min(best, squared(x, i, q));
        ASSERT_EQ(tree.nearest_squared(q), best) << kind << " n " << n;
        // Stopping early at `enough` gives a point within it whenever the nearest is.
        const double enough = 0.5;
        const double early = tree.nearest_squared(q, enough);
        if (best <= enough) EXPECT_LE(early, enough);
        else EXPECT_EQ(early, best);
        for (double extra : {0.0, 0.3, 5.0}) {
          const double r2 = best + extra;
          tree.within(q, r2, found);
          std::vector<GroundPointTree::Found> all;
          for (size_t k = 0; k < ids.size(); ++k)
            if (squared(x, ids[k], q) <= r2) all.push_back({int(k), squared(x, ids[k], q)});
          ASSERT_EQ(found.size(), all.size()) << kind << " n " << n << " r2 " << r2;
          for (size_t m = 0; m < all.size(); ++m) {
            EXPECT_EQ(found[m].index, all[m].index);
            EXPECT_EQ(found[m].squared, all[m].squared);
          }
          nonempty += !found.empty();
        }
      }
      EXPECT_GT(nonempty, 0);
    }
}

TEST(GroundPointTree, NoPointsHaveNoNearest) {
  GroundPointTree tree;
  tree.build(VecX::Zero(6), {});
  EXPECT_EQ(tree.nearest_squared(Vec2(1, 2)), std::numeric_limits<double>::infinity());
  std::vector<GroundPointTree::Found> found = {{0, 1.0}};
  tree.within(Vec2(1, 2), 100, found);
  EXPECT_TRUE(found.empty());
}

}  // namespace
}  // namespace kf
