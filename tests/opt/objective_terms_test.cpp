#include <gtest/gtest.h>

#include <algorithm>

#include "core/ground_region.h"

#include "opt/objective_terms.h"

namespace kf {
namespace {

// Central differences of a term's value against its gradient, in x and v.
void check_term(const ObjectiveSpec& spec, int p, unsigned seed) {
  auto term = make_objective_term(spec, p);
  std::srand(seed);
  VecX x = 2.0 * VecX::Random(3 * p), v = VecX::Random(3 * p);
  VecX gx = VecX::Zero(3 * p), gv = VecX::Zero(3 * p), dx(3 * p), dv(3 * p);
  term->eval(x, v, gx, gv);
  ASSERT_GT(gx.norm() + gv.norm(), 1e-6) << type_name(spec);
  VecX sx(3 * p), sv(3 * p);
  for (int k = 0; k < 3 * p; ++k) {
    for (int which = 0; which < 2; ++which) {
      VecX& q = which ? v : x;
      const double e = 1e-6, keep = q[k];
      q[k] = keep + e;
      const double fp = term->eval(x, v, sx.setZero(), sv.setZero());
      q[k] = keep - e;
      const double fm = term->eval(x, v, sx.setZero(), sv.setZero());
      q[k] = keep;
      (which ? dv : dx)[k] = (fp - fm) / (2 * e);
    }
  }
  EXPECT_LT((dx - gx).norm(), 1e-6 * std::max(1.0, gx.norm())) << type_name(spec);
  EXPECT_LT((dv - gv).norm(), 1e-6 * std::max(1.0, gv.norm())) << type_name(spec);
}

TEST(ObjectiveTerms, GradientsMatchFiniteDifferences) {
  ObjectiveSpec pos{.kind = PositionKeyframe{{Vec3(1, 2, 3), Vec3(0, 0, 1)}}, .frame = 1, .weight = 2.0, .particles = {1, 3}};
  ObjectiveSpec vel{.kind = VelocityKeyframe{{Vec3(0.2, 0, 0)}}, .frame = 1, .weight = 0.5};
  ObjectiveSpec com{.kind = CenterOfMassKeyframe{Vec3(0.5, 0.5, 0.5)}, .frame = 1, .weight = 3.0};
  ObjectiveSpec shape{.kind = ShapeKeyframe{{Vec2(-0.5, -0.5), Vec2(0.5, -0.5), Vec2(0.5, 0.5), Vec2(-0.5, 0.5)}},
                      .frame = 1, .weight = 1.5};
  ObjectiveSpec arch{.kind = ArchKeyframe{Vec3(0, -1, 0), Vec3(0, 0, 1), 1.5}, .frame = 1, .weight = 1.0};
  // A region larger than the agents' spread: its coverage term is active at several samples.
  ShapeKeyframe filled{{Vec2(-2.5, -2.5), Vec2(2.5, -2.5), Vec2(2.5, 2.5), Vec2(-2.5, 2.5)}, 0.3, 3.0, 0.7, 0.5};
  ObjectiveSpec coverage{.kind = filled, .frame = 1, .weight = 1.5};
  ObjectiveSpec height{.kind = HeightKeyframe{0.4}, .frame = 1, .weight = 2.5, .particles = {0, 2, 5}};
  for (unsigned seed : {1u, 2u, 3u})
    for (const auto& s : {pos, vel, com, shape, arch, coverage, height}) check_term(s, 6, seed);
}

// The height term ½w (ȳ − h)² against its definition and central differences at two step sizes, which
// agree with each other and with the gradient, at states away from the target (a sheet lifted, dropped,
// and its particles spread).
TEST(ObjectiveTerms, HeightMatchesItsDefinitionAndCentralDifferencesAtTwoSteps) {
  const int p = 7;
  const ObjectiveSpec spec{.kind = HeightKeyframe{0.8}, .frame = 3, .weight = 1.7, .particles = {1, 2, 4, 6}};
  const auto term = make_objective_term(spec, p);
  EXPECT_EQ(term->frame(), 3);
  for (unsigned seed : {4u, 5u, 6u}) {
    std::srand(seed);
    VecX x = 3.0 * VecX::Random(3 * p), v = VecX::Random(3 * p);
    x[3 * 1 + 1] += seed;  // one particle lifted well above the rest
    double mean = 0;
    for (int i : spec.particles) mean += x[3 * i + 1] / 4;
    VecX gx = VecX::Zero(3 * p), gv = VecX::Zero(3 * p);
    const double phi = term->eval(x, v, gx, gv);
    EXPECT_NEAR(phi, 0.5 * 1.7 * (mean - 0.8) * (mean - 0.8), 1e-12 * std::max(1.0, phi));
    EXPECT_EQ(gv.norm(), 0.0);
    ASSERT_GT(gx.norm(), 1e-3);
    VecX fd[2] = {VecX::Zero(3 * p), VecX::Zero(3 * p)};
    const double steps[2] = {1e-4, 1e-6};
    VecX sx(3 * p), sv(3 * p);
    for (int s = 0; s < 2; ++s)
      for (int k = 0; k < 3 * p; ++k) {
        const double keep = x[k];
        x[k] = keep + steps[s];
        const double fp = term->eval(x, v, sx.setZero(), sv.setZero());
        x[k] = keep - steps[s];
        const double fm = term->eval(x, v, sx.setZero(), sv.setZero());
        x[k] = keep;
        fd[s][k] = (fp - fm) / (2 * steps[s]);
      }
    EXPECT_LT((fd[0] - fd[1]).norm(), 1e-6 * gx.norm()) << seed;
    EXPECT_LT((fd[1] - gx).norm(), 1e-6 * gx.norm()) << seed;
    for (int i = 0; i < p; ++i) {  // only the listed particles' heights pull
      const bool listed = std::count(spec.particles.begin(), spec.particles.end(), i) > 0;
      EXPECT_EQ(gx[3 * i], 0.0);
      EXPECT_EQ(gx[3 * i + 2], 0.0);
      if (!listed) EXPECT_EQ(gx[3 * i + 1], 0.0);
    }
  }
}

TEST(ObjectiveTerms, CoverageIsZeroWhenTheRegionIsFilledAndPullsAnAgentIntoAGap) {
  const ShapeKeyframe square{{Vec2(0, 0), Vec2(2, 0), Vec2(2, 2), Vec2(0, 2)}, 0.0, 1.0, 0.75, 0.5};
  const std::vector<Vec2> samples = region_samples(square.polygon, 0.5);
  EXPECT_EQ(samples.size(), 16u);  // cell centres of a 4 x 4 grid: 0.25 ... 1.75
  // Four agents at the quarter centres cover every sample within 0.75 m.
  const std::vector<Vec2> at = {{0.5, 0.5}, {1.5, 0.5}, {0.5, 1.5}, {1.5, 1.5}};
  VecX x = VecX::Zero(12), v = VecX::Zero(12), gx = VecX::Zero(12), gv = gx;
  for (int i = 0; i < 4; ++i) x[3 * i] = at[i].x(), x[3 * i + 2] = at[i].y();
  ObjectiveSpec s{.kind = square, .frame = 1, .weight = 0.0};
  EXPECT_EQ(make_objective_term(s, 4)->eval(x, v, gx, gv), 0.0);
  EXPECT_EQ(gx.norm(), 0.0);
  // The agent of the top-right quarter moves to the bottom-left one: its corner is empty.
  x[9] = 0.6, x[11] = 0.4;
  const double val = make_objective_term(s, 4)->eval(x, v, gx, gv);
  EXPECT_GT(val, 0.0);
  // Descending the gradient moves the agents nearest the empty corner (1.75, 1.75) towards it: the one at
  // (1.5, 0.5) up in z, the one at (0.5, 1.5) along x.
  EXPECT_LT(gx[3 * 1 + 2], 0.0);
  EXPECT_LT(gx[3 * 2], 0.0);
}

TEST(ObjectiveTerms, ShapeIsZeroInsideAndPullsOutsidePointsToTheBoundary) {
  const std::vector<Vec2> cross = {{-1, -3}, {1, -3}, {1, -1}, {3, -1}, {3, 1}, {1, 1},
                                   {1, 3},   {-1, 3}, {-1, 1}, {-3, 1}, {-3, -1}, {-1, -1}};
  EXPECT_TRUE(polygon_contains(cross, Vec2(0, 0)));
  EXPECT_TRUE(polygon_contains(cross, Vec2(2.5, 0)));
  EXPECT_FALSE(polygon_contains(cross, Vec2(2, 2)));  // the notch between two arms
  const Vec2 p = closest_point_in_polygon(cross, Vec2(2, 2));
  EXPECT_NEAR((p - Vec2(2, 2)).norm(), 1.0, 1e-12);
  const Vec2 q = closest_point_in_polygon(cross, Vec2(0, 5));
  EXPECT_NEAR((q - Vec2(0, 3)).norm(), 0.0, 1e-12);
}

}  // namespace
}  // namespace kf
