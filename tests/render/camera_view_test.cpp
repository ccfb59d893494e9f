// Command-line cameras (--camera, --view) and the automatic framing, checked on rendered images: where a
// known object lands in a named view, and that a keyframe target at the scene's edge stays in the frame.
#include <gtest/gtest.h>

#include <cstdlib>

#include "../reliability/cli_harness.h"
#include "core/error.h"
#include "render/camera_choice.h"
#include "render/frame_renderer.h"
#include "render/image/image_diff.h"
#include "synthetic_runs.h"

namespace kf::render {
namespace {

namespace fs = std::filesystem;
constexpr int kW = 160, kH = 120;

// Pixel of world point p seen by `cam` in a kW x kH image (x right, y down); z: depth sign (> 0 in front).
Vec3 project(const Camera& cam, const Vec3& p) {
  const Eigen::Vector4d c = cam.projection(0.01, 1000.0) * cam.view() * Eigen::Vector4d(p.x(), p.y(), p.z(), 1.0);
  return Vec3((c.x() / c.w() + 1.0) * 0.5 * kW, (1.0 - c.y() / c.w()) * 0.5 * kH, c.w());
}

// Centre (column, row) and count of the pixels that `pick` accepts.
struct Blob {
  double x = 0, y = 0;
  int count = 0;
  int min_x = 1 << 30, max_x = -1, min_y = 1 << 30, max_y = -1;
};
template <class Pick>
Blob find_pixels(const Image& img, Pick pick) {
  Blob b;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const uint8_t* p = img.at(x, y);
      if (!pick(int(p[0]), int(p[1]), int(p[2]))) continue;
      b.x += x, b.y += y, ++b.count;
      b.min_x = std::min(b.min_x, x), b.max_x = std::max(b.max_x, x);
      b.min_y = std::min(b.min_y, y), b.max_y = std::max(b.max_y, y);
    }
  if (b.count) b.x /= b.count, b.y /= b.count;
  return b;
}
bool red(int r, int g, int b) { return r > 40 && r > 2 * g && r > 2 * b; }
bool green(int r, int g, int b) { return g > 90 && g > 2 * r && g > 2 * b; }

// The synthetic sheet (1.5 m square, about 1 m up) with a red sphere beside it at +x, +z, no ground.
RunData cloth_with_sphere(const fs::path& dir) {
  RunData run = load_run(testing::make_cloth_run(dir, 12));
  SphereShape s;
  s.center = Vec3(1.2, 0.3, 0.9);
  s.radius = 0.25;
  run.scene.cloth->colliders = {{s}};
  RenderSpec& rs = run.scene.render;
  rs.ground = false;
  rs.checker = 0;
  rs.collider_color = Vec3(0.9, 0.05, 0.05);
  rs.cloth_front = rs.cloth_back = Vec3(0.2, 0.3, 0.8);
  rs.background = Vec3(1, 1, 1);
  return run;
}

Image render_view(const RunData& run, const std::string& view) {
  FrameRenderer r(run, "osmesa", {kW, kH, 4}, parse_camera_choice("", view));
  return r.render(2);
}

TEST(CameraView, TopViewShowsXRightAndZDownTheImage) {
  testing::TempDir tmp;
  const RunData run = cloth_with_sphere(tmp.path() / "cloth");
  const Image top = render_view(run, "top");
  const Blob sphere = find_pixels(top, red);
  ASSERT_GT(sphere.count, 20) << "sphere not seen from above";
  EXPECT_GT(sphere.x, 0.6 * kW);  // +x: right
  EXPECT_GT(sphere.y, 0.6 * kH);  // +z: down the image, toward the viewer
  const Blob sheet = find_pixels(top, [](int r, int g, int b) { return b > 90 && b > 2 * r; });
  EXPECT_GT(sheet.count, 1000);
  EXPECT_LT(sheet.x, sphere.x);
  EXPECT_LT(sheet.y, sphere.y);
}

TEST(CameraView, NamedViewsPlaceTheSameObjectDifferently) {
  testing::TempDir tmp;
  const RunData run = cloth_with_sphere(tmp.path() / "cloth");
  const Blob front = find_pixels(render_view(run, "front"), red);
  const Blob side = find_pixels(render_view(run, "side"), red);
  ASSERT_GT(front.count, 20);
  ASSERT_GT(side.count, 20);
  EXPECT_GT(front.x, 0.6 * kW);  // front (eye on +z): +x to the right
  EXPECT_LT(side.x, 0.4 * kW);   // side (eye on +x): +z to the left
  // From the front and the side the sphere (0.3 m up) hangs below the sheet (1 m up).
  const Image front_img = render_view(run, "front");
  const Blob sheet = find_pixels(front_img, [](int r, int g, int b) { return b > 90 && b > 2 * r; });
  EXPECT_LT(sheet.y, front.y);
  const ImageDifference d = compare_images(render_view(run, "top"), front_img);
  EXPECT_GT(d.differing_fraction, 0.05);
}

TEST(CameraView, ExplicitCameraLooksWhereItIsTold) {
  testing::TempDir tmp;
  const RunData run = cloth_with_sphere(tmp.path() / "cloth");
  // Looking straight at the sphere from 3 m in front of it: it sits in the middle of the image.
  FrameRenderer r(run, "osmesa", {kW, kH, 4}, parse_camera_choice("eye=1.2,0.3,3.9 target=1.2,0.3,0.9 fov=30", ""));
  const Blob sphere = find_pixels(r.render(2), red);
  ASSERT_GT(sphere.count, 50);
  // Its outline (the lit side is brighter, so the box rather than the mean) is centred.
  EXPECT_NEAR(0.5 * (sphere.min_x + sphere.max_x), 0.5 * kW, 2.0);
  EXPECT_NEAR(0.5 * (sphere.min_y + sphere.max_y), 0.5 * kH, 2.0);
  // A narrower field of view makes it larger.
  FrameRenderer narrow(run, "osmesa", {kW, kH, 4}, parse_camera_choice("eye=1.2,0.3,3.9 target=1.2,0.3,0.9 fov=15", ""));
  EXPECT_GT(find_pixels(narrow.render(2), red).count, 3 * sphere.count);
}

// A flock whose triangle keyframe reaches far beyond the agents: its apex stays inside every framing.
TEST(CameraView, FramingKeepsAFarTargetInTheImage) {
  testing::TempDir tmp;
  RunData run = load_run(testing::make_flock_run(tmp.path() / "flock"));
  ShapeKeyframe tri;
  tri.polygon = {Vec2(-3, -3), Vec2(3, -3), Vec2(0, 16)};
  run.scene.objectives = {{tri, 5}};
  run.scene.render.target_color = Vec3(0.05, 0.9, 0.05);
  run.scene.render.agent_color = Vec3(0.1, 0.1, 0.1);
  const Vec3 apex(0, 0, 16);
  for (const std::string view : {"", "top", "three-quarter", "front", "side"}) {
    SCOPED_TRACE("view '" + view + "'");
    FrameRenderer r(run, "osmesa", {kW, kH, 4}, parse_camera_choice("", view));
    const Image img = r.render(5);
    const Blob marks = find_pixels(img, green);
    if (view == "front" || view == "side") continue;  // a line on the ground seen edge-on
    if (const char* keep = std::getenv("KEYFRAME_KEEP_IMAGES")) write_png(fs::path(keep) / ("framing_" + view + ".png"), img);
    ASSERT_GT(marks.count, 15);
    // No mark touches the border: nothing is cut off.
    EXPECT_GT(marks.min_x, 0);
    EXPECT_GT(marks.min_y, 0);
    EXPECT_LT(marks.max_x, kW - 1);
    EXPECT_LT(marks.max_y, kH - 1);
    const Vec3 a = project(r.camera(), apex);
    EXPECT_GT(a.z(), 0.0);
    EXPECT_GT(a.x(), 1.0);
    EXPECT_LT(a.x(), kW - 1.0);
    EXPECT_GT(a.y(), 1.0);
    EXPECT_LT(a.y(), kH - 1.0);
    // Green pixels at the apex's projection: the image shows the corner where the camera says it is.
    int close = 0;
    for (int y = std::max(0, int(a.y()) - 4); y <= std::min(kH - 1, int(a.y()) + 4); ++y)
      for (int x = std::max(0, int(a.x()) - 4); x <= std::min(kW - 1, int(a.x()) + 4); ++x) {
        const uint8_t* p = img.at(x, y);
        close += green(p[0], p[1], p[2]);
      }
    EXPECT_GT(close, 0) << "apex at pixel " << a.x() << ", " << a.y();
  }
}

// Every corner of the scene's box projects inside the image in every named view and the default one.
TEST(CameraView, EveryCornerOfTheBoundsIsInView) {
  Bounds b;
  b.add(Vec3(-8, 0, -3));
  b.add(Vec3(5, 2, 16));
  for (const bool flock : {true, false})
    for (const std::string view : {"", "front", "side", "top", "three-quarter"}) {
      SCOPED_TRACE("view '" + view + "'" + (flock ? " flock" : " cloth"));
      const Camera cam = make_camera(RenderSpec{}, b, flock, kW, kH, parse_camera_choice("", view));
      for (int k = 0; k < 8; ++k) {
        const Vec3 corner((k & 1) ? b.hi.x() : b.lo.x(), (k & 2) ? b.hi.y() : b.lo.y(), (k & 4) ? b.hi.z() : b.lo.z());
        const Vec3 q = project(cam, corner);
        EXPECT_GT(q.z(), 0.0);
        EXPECT_GE(q.x(), 0.0);
        EXPECT_LE(q.x(), kW);
        EXPECT_GE(q.y(), 0.0);
        EXPECT_LE(q.y(), kH);
      }
    }
}

TEST(CameraView, BadValuesAreOneLineErrors) {
  for (const char* bad : {"eye=0,1 target=0,0,0", "eye=0,1,2", "eye=a,1,2 target=0,0,0", "eye=0,0,0 target=0,0,0",
                          "eye=0,1,2 target=0,0,0 fov=200", "eye=0,1,2 target=0,0,0 zoom=2", "0,1,2"}) {
    SCOPED_TRACE(bad);
    try {
      parse_camera_choice(bad, "");
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      const std::string m = e.what();
      EXPECT_EQ(m.rfind("--camera: ", 0), 0u) << m;
      EXPECT_NE(m.find("eye=X,Y,Z target=X,Y,Z"), std::string::npos) << m;
      EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
  }
  EXPECT_THROW(parse_camera_choice("", "bottom"), InputError);
  EXPECT_THROW(parse_camera_choice("eye=0,1,2 target=0,0,0", "top"), InputError);
  EXPECT_EQ(parse_camera_choice("target=0,0,0  eye=0,5,0", "").camera->up, Vec3(0, 0, -1));  // looking down
}

class CameraCli : public reliability::TempDirTest {};

TEST_F(CameraCli, RenderRunAndFigureTakeTheOptionsAndRefuseBadOnesWithExit3) {
  testing::make_flock_run(dir_ / "flock");
  auto r = reliability::run_keyframe("render flock --size 64x48 --frames 0:1 --view top", dir_);
  ASSERT_EQ(r.code, kExitOk) << r.output;
  const Image top = read_png(dir_ / "flock/frames/frame_0000.png");
  r = reliability::run_keyframe("render flock --size 64x48 --frames 0:1 --camera 'eye=0,3,25 target=0,0,0 fov=30'", dir_);
  ASSERT_EQ(r.code, kExitOk) << r.output;
  EXPECT_GT(compare_images(top, read_png(dir_ / "flock/frames/frame_0000.png")).differing_fraction, 0.05);
  r = reliability::run_keyframe("figure flock --size 64x48 --frames 0 --view side --out-dir figs", dir_);
  ASSERT_EQ(r.code, kExitOk) << r.output;
  EXPECT_TRUE(fs::exists(dir_ / "figs/flock.png"));
  for (const char* bad : {"render flock --view bottom", "render flock --camera 'eye=1,2 target=0,0,0'",
                          "figure flock --camera 'eye=0,0,0 target=0,0,0' --out-dir figs2",
                          "run flock --view diagonal", "render flock --view top --camera 'eye=0,1,2 target=0,0,0'"}) {
    SCOPED_TRACE(bad);
    r = reliability::run_keyframe(bad, dir_);
    EXPECT_EQ(r.code, kExitInput) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  }
  EXPECT_FALSE(fs::exists(dir_ / "figs2"));
}

}  // namespace
}  // namespace kf::render
