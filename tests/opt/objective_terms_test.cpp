#include <gtest/gtest.h>

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
  for (unsigned seed : {1u, 2u, 3u})
    for (const auto& s : {pos, vel, com, shape, arch}) check_term(s, 6, seed);
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
