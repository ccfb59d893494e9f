// Cape anchor vertices: where they are in the bind pose and that they follow the body.
#include <gtest/gtest.h>

#include <cstdio>

#include "core/error.h"
#include "sim/character/cape_anchors.h"
#include "character_test_util.h"

namespace kf {
namespace {

TEST(CapeAnchors, NearTheirTargetsOnTheTorsoBack) {
  Character c(test::character_asset());
  const std::vector<int> anchors = cape_anchor_vertices(c);
  const std::vector<Vec3> targets = cape_anchor_targets();
  ASSERT_EQ(anchors.size(), targets.size());
  for (size_t i = 0; i < anchors.size(); ++i) {
    EXPECT_GE(anchors[i], c.mesh_vertex_begin()[0]);
    EXPECT_LT(anchors[i], c.mesh_vertex_begin()[1]);  // Torso is the first mesh
    const Vec3 p = seg(c.bind_vertices(), anchors[i]);
    std::printf("anchor %zu: vertex %d at (%.3f, %.3f, %.3f), %.1f mm from its target\n", i, anchors[i], p.x(), p.y(),
                p.z(), 1e3 * (p - targets[i]).norm());
    EXPECT_LT((p - targets[i]).norm(), 0.03) << "anchor " << i << " at " << p.transpose();
    EXPECT_LT(p.z(), -0.15);  // on the back
    if (i > 0) {
      EXPECT_GT(p.x(), seg(c.bind_vertices(), anchors[i - 1]).x());
    }
  }
}

TEST(CapeAnchors, FollowTheBodyUpInTheJump) {
  Character c(test::character_asset());
  const std::vector<int> anchors = cape_anchor_vertices(c);
  VecX x0, x1, a0, a1;
  c.pose(0.0, x0);
  c.pose(1.7, x1);  // the top of the jump: the pelvis is 0.41 m higher
  gather_vertices(x0, anchors, a0);
  gather_vertices(x1, anchors, a1);
  ASSERT_EQ(a1.size(), 15);
  const double rise = c.node_world(c.node_index("B_Root_Pelvis_L"), 1.7).translation().y() -
                      c.node_world(c.node_index("B_Root_Pelvis_L"), 0.0).translation().y();
  ASSERT_GT(rise, 0.3);
  for (int i = 0; i < 5; ++i) EXPECT_NEAR(a1[3 * i + 1] - a0[3 * i + 1], rise, 0.1) << "anchor " << i;
}

TEST(CapeAnchors, UnknownMeshIsAnInputError) {
  Character c(test::character_asset());
  EXPECT_THROW(nearest_bind_vertices(c, cape_anchor_targets(), "Cape"), InputError);
}

}  // namespace
}  // namespace kf
