// Closest points on the posed body: Embree point queries against brute force, and the triangle kernel.
#include <gtest/gtest.h>

#include <random>

#include "sim/character/body_query.h"
#include "sim/character/character.h"
#include "sim/character/closest_point_triangle.h"
#include "character_test_util.h"

namespace kf {
namespace {

TEST(ClosestPointOnTriangle, NoSampledTrianglePointIsCloser) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int features_seen[7] = {};
  for (int trial = 0; trial < 300; ++trial) {
    const Vec3 a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng)), c(u(rng), u(rng), u(rng));
    const Vec3 p = 1.5 * Vec3(u(rng), u(rng), u(rng));
    const TrianglePoint tp = closest_point_on_triangle(p, a, b, c);
    ++features_seen[static_cast<int>(tp.feature)];
    EXPECT_LT((tp.barycentric[0] * a + tp.barycentric[1] * b + tp.barycentric[2] * c - tp.point).norm(), 1e-12);
    EXPECT_NEAR(tp.barycentric.sum(), 1.0, 1e-12);
    EXPECT_GE(tp.barycentric.minCoeff(), -1e-12);
    const double d = (p - tp.point).norm();
    const int n = 60;
    double sampled = 1e9;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) {
        const Vec3 q = a + (double(i) / n) * (b - a) + (double(j) / n) * (c - a);
        sampled = std::min(sampled, (p - q).norm());
      }
    EXPECT_LE(d, sampled + 1e-12);
    EXPECT_GT(d, sampled - 0.05);  // the grid spacing bounds how much closer the true point can be
  }
  // The random cases reach the face and edge/vertex regions, so each branch was exercised.
  EXPECT_GT(features_seen[static_cast<int>(TriangleFeature::kFace)], 0);
  EXPECT_GT(features_seen[1] + features_seen[2] + features_seen[3], 0);
  EXPECT_GT(features_seen[4] + features_seen[5] + features_seen[6], 0);
}

TEST(BodyQuery, EqualsBruteForceOnRandomPointsForSeveralPoses) {
  Character character(test::character_asset());
  BodyQuery query(character.triangles(), character.vertex_count());
  std::mt19937 rng(11);
  VecX x;
  for (double t : {0.0, 0.8, 1.7, 2.6}) {
    character.pose(t, x);
    query.update(x);
    Vec3 lo = Vec3::Constant(1e9), hi = Vec3::Constant(-1e9);
    for (int v = 0; v < character.vertex_count(); ++v) lo = lo.cwiseMin(seg(x, v)), hi = hi.cwiseMax(seg(x, v));
    std::uniform_real_distribution<double> ux(lo.x() - 0.2, hi.x() + 0.2), uy(lo.y() - 0.2, hi.y() + 0.2),
        uz(lo.z() - 0.2, hi.z() + 0.2);
    int found = 0, missed = 0, inside = 0;
    for (int i = 0; i < 300; ++i) {
      const Vec3 p(ux(rng), uy(rng), uz(rng));
      const double radius = 0.15;
      const BodyHit fast = query.closest(p, radius);
      const BodyHit slow = query.surface().closest_brute_force(p, radius);
      ASSERT_EQ(fast.found(), slow.found()) << "t = " << t << " p = " << p.transpose();
      if (!slow.found()) {
        ++missed;
        continue;
      }
      ++found;
      inside += slow.signed_distance < 0.0;
      EXPECT_NEAR(fast.distance, slow.distance, 1e-12) << "t = " << t << " p = " << p.transpose();
      // Ties between triangles sharing the closest edge or vertex give the same point and normal.
      EXPECT_LT((fast.point - slow.point).norm(), 1e-9);
      EXPECT_LT((fast.normal - slow.normal).norm(), 1e-9);
      EXPECT_EQ(fast.signed_distance, slow.signed_distance);
      EXPECT_NEAR(fast.normal.norm(), 1.0, 1e-12);
      EXPECT_LE(fast.distance, radius);
    }
    // Both outcomes and both sides of the surface occur, so the comparison covers them all.
    EXPECT_GT(found, 30) << "t = " << t;
    EXPECT_GT(missed, 30) << "t = " << t;
    EXPECT_GT(inside, 0) << "t = " << t;
  }
}

TEST(BodyQuery, SignedDistanceAndNormalAlongTheChestNormal) {
  Character character(test::character_asset());
  BodyQuery query(character.triangles(), character.vertex_count());
  VecX x;
  character.pose(0.0, x);
  query.update(x);
  // A face on the chest: the torso triangle whose centroid is furthest forward.
  int chest = 0;
  double best_z = -1e9;
  for (int f = 0; f < character.triangle_count(); ++f) {
    if (character.triangles()(f, 0) >= character.mesh_vertex_begin()[1]) continue;
    double z = 0.0;
    for (int k = 0; k < 3; ++k) z += x[3 * character.triangles()(f, k) + 2] / 3.0;
    if (z > best_z) best_z = z, chest = f;
  }
  const Vec3 n = query.surface().face_normal(chest);
  ASSERT_GT(n.z(), 0.5);  // faces the front
  Vec3 centroid = Vec3::Zero();
  for (int k = 0; k < 3; ++k) centroid += seg(x, character.triangles()(chest, k)) / 3.0;
  const BodyHit out = query.closest(centroid + 0.01 * n, 0.1);
  ASSERT_TRUE(out.found());
  EXPECT_NEAR(out.signed_distance, 0.01, 1e-6);
  EXPECT_GT(out.normal.dot(n), 0.999);
  const BodyHit in = query.closest(centroid - 0.002 * n, 0.1);
  ASSERT_TRUE(in.found());
  EXPECT_LT(in.signed_distance, 0.0);
  EXPECT_GT(in.normal.dot(n), 0.99);  // still outward: the way to push a particle back out
  EXPECT_FALSE(query.closest(centroid + 0.05 * n, 0.04).found());
}

TEST(BodyQuery, BatchEqualsSingleQueries) {
  Character character(test::character_asset());
  BodyQuery query(character.triangles(), character.vertex_count());
  VecX x;
  character.pose(1.2, x);
  query.update(x);
  // A 16 x 26 sheet behind the back, like the cape.
  VecX points(3 * 16 * 26);
  for (int i = 0; i < 16; ++i)
    for (int j = 0; j < 26; ++j) seg(points, i * 26 + j) = Vec3(-0.3 + 0.04 * i, 0.8 - 0.04 * j, -0.3);
  std::vector<BodyHit> hits;
  query.closest_batch(points, 0.2, hits);
  ASSERT_EQ(hits.size(), 416u);
  int found = 0;
  for (int i = 0; i < 416; ++i) {
    const BodyHit one = query.closest(seg(points, i), 0.2);
    ASSERT_EQ(one.found(), hits[i].found());
    found += one.found();
    if (one.found()) {
      EXPECT_EQ(one.triangle, hits[i].triangle);
      EXPECT_EQ(one.distance, hits[i].distance);
    }
  }
  EXPECT_GT(found, 100);
}

}  // namespace
}  // namespace kf
