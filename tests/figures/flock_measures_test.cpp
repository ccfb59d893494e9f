// The flock's figure measures that compare agents with each other or with sample points (nearest spacing,
// coverage) use a neighbour grid; they must give exactly what comparing every pair gives.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "opt/keyframes/ground_spacing.h"
#include "report/figure_measures.h"
#include "scene/scene.h"
#include "../sim/random_flock.h"

namespace kf {
namespace {

TEST(FlockMeasures, NearestSpacingEqualsAllPairs) {
  std::mt19937_64 rng(3);
  int far_checked = 0;
  for (int p : {1, 2, 3, 50, 1500})
    for (double box : {0.2, 10.0, 300.0}) {
      VecX x = random_planar(p, box, rng);
      if (p > 10) {
        seg(x, 1) = seg(x, 0);                        // coincident: spacing 0
        seg(x, 2) = Vec3(50 * box, 0, -40 * box);     // a stray far beyond every other agent
        seg(x, 3) = Vec3(-3 * box, 0, 2 * box);       // and one outside the cluster
        for (int i = 4; i < p / 2; ++i) x[3 * i] *= 0.01;  // half of them bunched in a strip
      }
      const std::vector<double> got = nearest_neighbour_spacing(x);
      ASSERT_EQ(int(got.size()), p);
      for (int i = 0; i < p; ++i) {
        double want = std::numeric_limits<double>::infinity();
        for (int j = 0; j < p; ++j)
          if (j != i) want = std::min(want, std::hypot(x[3 * i] - x[3 * j], x[3 * i + 2] - x[3 * j + 2]));
        ASSERT_EQ(got[i], want) << "p " << p << " box " << box << " agent " << i;
      }
      if (p > 10) {
        EXPECT_EQ(got[0], 0.0);
        far_checked += got[2] > 10 * box;
      }
    }
  EXPECT_EQ(far_checked, 6) << "the strays must have no neighbour near them";
}

TEST(FlockMeasures, PointsCoveredEqualsAllPairs) {
  std::mt19937_64 rng(4);
  long covered = 0, points = 0;
  for (int p : {0, 1, 40, 2000})
    for (double radius : {0.3, 1.5}) {
      const VecX x = random_planar(p, 20.0, rng);
      std::vector<Vec2> q;
      for (double a = -25; a <= 25; a += 0.5)
        for (double b = -25; b <= 25; b += 0.5) q.emplace_back(a, b);
      if (p > 0) q.emplace_back(x[0] + radius, x[2]);  // at the radius, up to rounding
      const std::vector<char> got = points_covered(x, q, radius);
      ASSERT_EQ(got.size(), q.size());
      for (size_t k = 0; k < q.size(); ++k) {
        bool want = false;
        for (int i = 0; i < p && !want; ++i)
          want = Vec2(x[3 * i] - q[k].x(), x[3 * i + 2] - q[k].y()).squaredNorm() <= radius * radius;
        ASSERT_EQ(bool(got[k]), want) << "p " << p << " radius " << radius << " point " << k;
        covered += want;
      }
      points += long(q.size());
    }
  EXPECT_GT(covered, 1000);
  EXPECT_LT(covered, points / 2);
}

// A crowd's shape can hold more samples at its coverage spacing than a region may have (100,000): its report
// coarsens the spacing rather than failing after the optimisation (a 100,000-agent square, 313 m wide).
TEST(FlockMeasures, AShapeTooLargeForItsSpacingIsMeasuredMoreCoarsely) {
  const Scene scene = parse_scene(R"({"time": {"frames": 1}, "flock": {"agents": 4, "spawn": {"radius": 2}},
      "objectives": [{"type": "shape", "frame": 1, "polygon": [[0, 0], [313, 0], [313, 313], [0, 313]]}]})",
                                  "crowd.json");
  Trajectory t;
  t.particles = 4;
  VecX x(12);
  x << 1, 0, 1, 2, 0, 2, 400, 0, 1, 3, 0, 3;
  t.x = {x, x};
  t.v = {VecX::Zero(12), VecX::Zero(12)};
  const auto m = figure_measures(scene, t);
  ASSERT_TRUE(m.is_array() && !m.empty()) << m.dump();
  EXPECT_DOUBLE_EQ(m[0]["inside_fraction"].get<double>(), 0.75);
  const double spacing = m[0]["coverage_spacing"].get<double>();
  EXPECT_GT(spacing, 0.75);
  EXPECT_LE(std::pow(std::round(313 / spacing), 2), 1e5);
  EXPECT_GT(m[0]["coverage_fraction"].get<double>(), 0.0);
  EXPECT_LT(m[0]["coverage_fraction"].get<double>(), 1e-3);
}

}  // namespace
}  // namespace kf
