// Shape keyframes with holes (a ring, and a polygon hole cut from it): agents in a hole are outside the
// region and pulled out of it, agents inside within the margin of a hole's edge are pulled away from it,
// coverage samples leave the holes empty, and the gradient matches central differences at two steps.
#include <gtest/gtest.h>

#include <cmath>

#include "core/ground_region.h"
#include "core/trajectory.h"
#include "opt/objective_terms.h"
#include "report/figure_measures.h"
#include "scene/scene.h"

namespace kf {
namespace {

constexpr int kSegments = 32;

std::vector<Vec2> circle(double r) {
  std::vector<Vec2> loop;
  for (int i = 0; i < kSegments; ++i)
    loop.emplace_back(r * std::cos(2 * M_PI * i / kSegments), r * std::sin(2 * M_PI * i / kSegments));
  return loop;
}

// A ring from 1 to 3 m with a 0.6 m square hole cut from its right side.
ShapeKeyframe ring_with_square_hole() {
  ShapeKeyframe k;
  k.polygon = circle(3.0);
  k.holes = {circle(1.0), {{1.6, -0.3}, {2.2, -0.3}, {2.2, 0.3}, {1.6, 0.3}}};
  k.margin = 0.2;
  k.coverage_weight = 2.0;
  k.coverage_radius = 0.8;
  k.coverage_spacing = 0.4;
  return k;
}

// A point at radius r on the ray through the middle of edge `edge` of the 32-gons: away from the rays
// through their corners, where the distance to a polygon from inside has a kink.
Vec2 mid_edge(double r, int edge) {
  const double a = 2 * M_PI * (edge + 0.5) / kSegments;
  return {r * std::cos(a), r * std::sin(a)};
}

// Agents in the ring's hole, inside near the hole's edge (within the margin), deep inside, near and beyond
// the outer edge, in the square hole and inside just beside it.
const std::vector<Vec2> kAgents = {mid_edge(0.4, 3),  mid_edge(0.7, 12), mid_edge(1.1, 20), mid_edge(2.0, 9),
                                   mid_edge(2.9, 25), mid_edge(3.5, 16), mid_edge(4.2, 29), {1.75, 0.05},
                                   {2.3, 0.05}};

VecX positions(const std::vector<Vec2>& at) {
  VecX x = VecX::Zero(3 * at.size());
  for (size_t i = 0; i < at.size(); ++i) x[3 * i] = at[i].x(), x[3 * i + 2] = at[i].y();
  return x;
}

TEST(ShapeHoles, AgentsInAHoleAreOutsideAndPulledOutOfIt) {
  const ShapeKeyframe k = ring_with_square_hole();
  const GroundRegion region(k.polygon, k.holes);
  EXPECT_FALSE(polygon_contains(region, {0, 0}));     // the ring's hole
  EXPECT_FALSE(polygon_contains(region, {1.9, 0}));   // the square hole
  EXPECT_TRUE(polygon_contains(region, {-2, 0}));     // in the ring
  EXPECT_TRUE(polygon_contains(region, {2.4, 0}));    // beside the square hole
  EXPECT_FALSE(polygon_contains(region, {3.5, 0}));   // beyond the ring
  ShapeKeyframe pull_only = k;  // coverage off: the pulls below are the inside and margin terms' alone
  pull_only.coverage_weight = 0;
  const ObjectiveSpec s{.kind = pull_only, .frame = 1, .weight = 1.0};
  const int p = int(kAgents.size());
  const VecX x = positions(kAgents), v = VecX::Zero(3 * p);
  VecX gx = VecX::Zero(3 * p), gv = gx;
  make_objective_term(s, p)->eval(x, v, gx, gv);
  auto pull = [&](int i) -> Vec2 { return -Vec2(gx[3 * i], gx[3 * i + 2]); };  // the descent direction
  // In the ring's hole: pushed outward to the inner circle (0.6 m from it plus the 0.2 m margin).
  EXPECT_GT(pull(0).dot(kAgents[0].normalized()), 0.5);
  EXPECT_GT(pull(1).dot(kAgents[1].normalized()), 0.4);
  // Inside, 0.1 m from the inner circle (within the 0.2 m margin): pushed away from it, outward.
  EXPECT_GT(pull(2).dot(kAgents[2].normalized()), 0.0);
  // In the square hole 0.15 m from its left edge: pulled left, out through that edge.
  EXPECT_LT(pull(7).x(), -0.3);
  // Inside, 0.1 m right of the square hole: pushed right, away from it.
  EXPECT_GT(pull(8).x(), 0.05);
  // Beyond the ring: pulled inward.
  EXPECT_LT(pull(6).dot(kAgents[6].normalized()), -1.0);
}

TEST(ShapeHoles, GradientMatchesCentralDifferencesAtTwoSteps) {
  const ObjectiveSpec s{.kind = ring_with_square_hole(), .frame = 1, .weight = 1.5};
  const int p = int(kAgents.size());
  auto term = make_objective_term(s, p);
  for (unsigned seed : {1u, 2u}) {
    // The agents above moved by up to 2 cm (seeded), so no check sits on a hand-picked point only.
    std::srand(seed);
    VecX x = positions(kAgents) + 0.02 * VecX::Random(3 * p), v = VecX::Zero(3 * p);
    VecX gx = VecX::Zero(3 * p), gv = gx;
    const double val = term->eval(x, v, gx, gv);
    ASSERT_GT(val, 0);
    ASSERT_GT(gx.norm(), 1.0);
    double worst[2] = {0, 0};
    const double steps[2] = {1e-5, 1e-6};
    for (int k = 0; k < 3 * p; ++k) {
      double fd[2];
      for (int h = 0; h < 2; ++h) {
        VecX e = VecX::Zero(3 * p), g1 = gx, g2 = gv;
        e[k] = steps[h];
        fd[h] = (term->eval(x + e, v, g1, g2) - term->eval(x - e, v, g1, g2)) / (2 * steps[h]);
        worst[h] = std::max(worst[h], std::abs(fd[h] - gx[k]) / std::max(1.0, std::abs(gx[k])));
      }
      EXPECT_NEAR(fd[0], fd[1], 1e-6 * std::max(1.0, std::abs(gx[k]))) << "component " << k << ": steps disagree";
    }
    EXPECT_LT(worst[0], 1e-6) << "seed " << seed;
    EXPECT_LT(worst[1], 1e-6) << "seed " << seed;
  }
}

TEST(ShapeHoles, CoverageSamplesAndTheInsideMeasureLeaveHolesOut) {
  const ShapeKeyframe k = ring_with_square_hole();
  const GroundRegion region(k.polygon, k.holes);
  const std::vector<Vec2> samples = region_samples(region, 0.1);
  for (const Vec2& q : samples) {
    EXPECT_GT(q.norm(), 0.99);
    EXPECT_FALSE(std::abs(q.x() - 1.9) < 0.3 && std::abs(q.y()) < 0.3) << q.transpose();
  }
  // The samples' area against the region's: the 32-gons' areas less the square's.
  const double gon = [](double r) { return 0.5 * kSegments * r * r * std::sin(2 * M_PI / kSegments); }(1.0);
  const double area = gon * 9 - gon - 0.36;
  EXPECT_NEAR(samples.size() * 0.01, area, 0.01 * area);

  // A scene's ring keyframe, measured on a frame with 3 of its 9 agents in a hole and 1 beyond it.
  const Scene scene = parse_scene(R"({"time": {"frames": 1}, "flock": {"agents": 9, "spawn": {"radius": 20}},
      "objectives": [{"type": "shape", "frame": 1, "ring": {"center": [0, 0], "inner_radius": 1, "outer_radius": 3},
                      "holes": [{"polygon": [[1.6, -0.3], [2.2, -0.3], [2.2, 0.3], [1.6, 0.3]]}]}]})",
                                  "ring.json");
  const std::vector<Vec2> at = {{0, 0},   {0.5, 0.2}, {1.9, 0},  {-2, 0}, {0, 2},
                                {0, -1.5}, {2.5, 0},   {-1, -1}, {3.5, 0}};
  Trajectory t;
  t.particles = 9;
  t.x = {positions(at), positions(at)};
  t.v = {VecX::Zero(27), VecX::Zero(27)};
  const auto m = figure_measures(scene, t);
  ASSERT_TRUE(m.is_array() && !m.empty()) << m.dump();
  EXPECT_DOUBLE_EQ(m[0]["inside_fraction"].get<double>(), 5.0 / 9.0) << m.dump();
}

}  // namespace
}  // namespace kf
