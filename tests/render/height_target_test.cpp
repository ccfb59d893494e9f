// A height keyframe's target is drawn as the other kinds' are, while it is still to come: a level outline
// at the target height around its particles, in the target colour; and the camera's bounds keep it in view.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "render/frame_range_bounds.h"
#include "render/geometry/frame_geometry.h"
#include "synthetic_runs.h"

namespace kf::render {
namespace {

namespace fs = std::filesystem;

// The vertices of `m` drawn in `color` (front side).
std::vector<Vec3> vertices_in(const Mesh& m, const Vec3& color) {
  std::vector<Vec3> out;
  for (const Vertex& v : m.vertices)
    if ((Vec3(v.front[0], v.front[1], v.front[2]) - color).norm() < 1e-6) out.emplace_back(v.p[0], v.p[1], v.p[2]);
  return out;
}

// The synthetic 8 x 8 sheet (about 1 m up, 1.5 m square) whose first row (z = -0.75) is asked up to 1.6 m
// at frame 3.
struct HeightRun {
  testing::TempDir tmp;
  fs::path run = testing::make_cloth_run(tmp.path() / "cloth", 8);
  Scene scene;
  Trajectory traj;
  HeightRun() {
    testing::write_text(run / "scene.json", R"({"time": {"frames": 5}, "cloth": {"nx": 8, "ny": 8},
      "objectives": [{"type": "height", "frame": 3, "particles": [0, 1, 2, 3, 4, 5, 6, 7], "height": 1.6}]})");
    scene = load_scene(run / "scene.json");
    traj = load_trajectory(run / "trajectory.bin");
  }
};

TEST(HeightTarget, ALevelOutlineAroundItsParticlesUntilItsFrame) {
  const HeightRun h;
  const Bounds bounds = scene_bounds(h.scene, h.traj);
  for (int frame : {0, 2, 3}) {
    SCOPED_TRACE("frame " + std::to_string(frame));
    FrameGeometry g;
    build_frame_geometry(h.scene, h.traj, frame, bounds, g);
    const std::vector<Vec3> drawn = vertices_in(g.objects, h.scene.render.target_color);
    ASSERT_GE(drawn.size(), 8u);
    double lo_x = 1e9, hi_x = -1e9, lo_z = 1e9, hi_z = -1e9;
    for (const Vec3& p : drawn) {
      EXPECT_NEAR(p.y(), 1.6, 1e-6);  // level, at the target height
      lo_x = std::min(lo_x, p.x()), hi_x = std::max(hi_x, p.x()), lo_z = std::min(lo_z, p.z()), hi_z = std::max(hi_z, p.z());
    }
    // Around the first row (x from -0.75 to 0.75 at z = -0.75), a little wider, not around the whole sheet.
    EXPECT_LT(lo_x, -0.75);
    EXPECT_GT(hi_x, 0.75);
    EXPECT_LT(lo_z, -0.75);
    EXPECT_GT(hi_z, -0.75);
    EXPECT_LT(hi_x - lo_x, 2.0);
    EXPECT_LT(hi_z - lo_z, 0.5);
  }
  FrameGeometry after;
  build_frame_geometry(h.scene, h.traj, 4, bounds, after);
  EXPECT_TRUE(vertices_in(after.objects, h.scene.render.target_color).empty()) << "drawn after its frame";
}

TEST(HeightTarget, TheCameraBoundsHoldTheTargetHeight) {
  const HeightRun h;
  // The sheet itself stays below 1.2 m: only the target reaches 1.6 m.
  EXPECT_NEAR(scene_bounds(h.scene, h.traj).hi.y(), 1.6, 1e-12);
  EXPECT_NEAR(frame_range_bounds(h.scene, h.traj, nullptr, 0, 4).hi.y(), 1.6, 1e-12);
  EXPECT_LT(frame_range_bounds(h.scene, h.traj, nullptr, 4, -1).hi.y(), 1.2);  // its frame not in the range
}

}  // namespace
}  // namespace kf::render
