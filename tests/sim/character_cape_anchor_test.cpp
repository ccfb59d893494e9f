// Cape anchor vertices: where they are in the bind pose and that they follow the body.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "core/error.h"
#include "scene/scene.h"
#include "sim/character/cape_anchors.h"
#include "sim/character/scene_character.h"
#include "character_test_util.h"

namespace kf {
namespace {

// The anchors shipped beside the character mesh.
CapeAnchors shipped_anchors() { return load_cape_anchors(cape_anchors_file(test::character_asset())); }

TEST(CapeAnchors, NearTheirTargetsOnTheTorsoBack) {
  Character c(test::character_asset());
  const std::vector<Vec3> targets = shipped_anchors().points;
  const std::vector<int> anchors = cape_anchor_vertices(c, shipped_anchors());
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
  const std::vector<int> anchors = cape_anchor_vertices(c, shipped_anchors());
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
  EXPECT_THROW(nearest_bind_vertices(c, shipped_anchors().points, "Cape"), InputError);
}

// The anchors are data: the file beside the mesh by default, the scene's "anchors" block when given, and no
// anchors ("none") when neither exists.
TEST(CapeAnchors, ReadFromTheSceneOrTheFileBesideTheMesh) {
  test::TempDir tmp;
  std::filesystem::copy_file(cape_anchors_file(test::character_asset()), tmp.path() / "body.cape.json");
  // The meshes exist (a missing mesh is refused on /character/file first); parsing never opens them.
  for (const char* mesh : {"body.X", "other.X"}) std::ofstream(tmp.path() / mesh) << "xof 0303txt 0032\n";
  const auto scene_with = [&](const std::string& character) {
    return R"({"time": {"fps": 30, "frames": 2}, "cloth": {"nx": 4, "ny": 4}, "character": )" + character + "}";
  };
  const Scene beside = parse_scene(scene_with(R"({"file": "body.X"})"), tmp.path() / "a.json");
  EXPECT_EQ(beside.character->anchors.mesh, "Torso");
  ASSERT_EQ(beside.character->anchors.points.size(), 5u);
  EXPECT_EQ(beside.character->anchors.points[2], Vec3(0.0, 0.50, -0.24));

  const Scene stated = parse_scene(
      scene_with(R"({"file": "body.X", "anchors": {"points": [[-0.1, 0.4, -0.2], [0.1, 0.4, -0.2]]}})"),
      tmp.path() / "b.json");
  EXPECT_EQ(stated.character->anchors.mesh, "");
  ASSERT_EQ(stated.character->anchors.points.size(), 2u);
  EXPECT_EQ(stated.character->anchors.points[1], Vec3(0.1, 0.4, -0.2));

  // Neither a block nor a file beside the mesh, or "none": the cloth is not pinned to the body.
  EXPECT_FALSE(beside.character->anchors.none);
  EXPECT_FALSE(stated.character->anchors.none);
  EXPECT_TRUE(parse_scene(scene_with(R"({"file": "other.X"})"), tmp.path() / "c.json").character->anchors.none);
  EXPECT_TRUE(parse_scene(scene_with(R"({"file": "body.X", "anchors": "none"})"), tmp.path() / "c.json")
                  .character->anchors.none);
  EXPECT_THROW(parse_scene(scene_with(R"({"file": "body.X", "anchors": "shoulders"})"), tmp.path() / "c.json"),
               InputError);
  EXPECT_THROW(parse_scene(scene_with(R"({"file": "body.X", "anchors": {"points": [[0, 0, 0]]}})"),
                           tmp.path() / "d.json"),
               InputError);  // one point cannot span an edge
}

// A keyed root motion moves the whole posed body rigidly: translation and angle interpolate linearly between
// keys and hold outside them; the pins (the anchors) move with it.
TEST(CharacterRootMotion, InterpolatesKeysAndMovesThePosedBodyRigidly) {
  test::TempDir tmp;
  std::filesystem::copy_file(cape_anchors_file(test::character_asset()), tmp.path() / "body.cape.json");
  // The meshes exist (a missing mesh is refused on /character/file first); parsing never opens them.
  for (const char* mesh : {"body.X", "other.X"}) std::ofstream(tmp.path() / mesh) << "xof 0303txt 0032\n";
  const Scene scene = parse_scene(R"({"time": {"fps": 30, "frames": 2}, "cloth": {"nx": 4, "ny": 4},
    "character": {"file": "body.X", "offset": [0, 1, 0],
      "root": {"pivot": [0, -1, 0], "axis": [2, 0, 0],
               "keys": [{"frame": 0, "translate": [0, 2, 0]}, {"frame": 10, "angle": 90}]}}})",
                                  tmp.path() / "fall.json");
  const CharacterSpec& spec = *scene.character;
  // Frame 5: translation (0, 1, 0), 45 degrees about +x through (0, -1, 0), then the offset.
  const Vec3 p(0.3, 0.5, -0.2);
  const double c = std::cos(M_PI / 4), s = std::sin(M_PI / 4);
  const Vec3 rel = p - Vec3(0, -1, 0);
  const Vec3 expect = Vec3(0, -1, 0) + Vec3(rel.x(), c * rel.y() - s * rel.z(), s * rel.y() + c * rel.z()) +
                      Vec3(0, 1, 0) + Vec3(0, 1, 0);
  EXPECT_LT((character_placement(spec, 5) * p - expect).norm(), 1e-12);
  EXPECT_LT((character_placement(spec, -3) * p - (p + Vec3(0, 3, 0))).norm(), 1e-12);  // held before
  EXPECT_LT((character_placement(spec, 10) * p - character_placement(spec, 40) * p).norm(), 1e-15);  // and after

  Character body(test::character_asset(), character_options(spec));
  VecX still, moved;
  body.pose(animation_time(spec, 5), still);
  pose_at_frame(body, spec, 5, moved);
  const Eigen::Affine3d m = character_placement(spec, 5) * body.placement().inverse();
  for (int i : {0, 100, body.vertex_count() - 1})
    EXPECT_LT((seg(moved, i) - m * Vec3(seg(still, i))).norm(), 1e-12) << "vertex " << i;
  // Rigid: distances between vertices are kept.
  EXPECT_NEAR((seg(moved, 0) - seg(moved, 100)).norm(), (seg(still, 0) - seg(still, 100)).norm(), 1e-12);

  EXPECT_THROW(parse_scene(R"({"time": {"fps": 30, "frames": 2}, "cloth": {"nx": 4, "ny": 4},
    "character": {"file": "body.X", "root": {"keys": [{"frame": 3}, {"frame": 3}]}}})",
                           tmp.path() / "bad.json"),
               InputError);
}

}  // namespace
}  // namespace kf
