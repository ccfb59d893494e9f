// meshes.bin: round trip, one clear error per kind of damage, and bodies drawn by both back ends.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>

#include "core/error.h"
#include "core/mesh_sequence.h"
#include "render/frame_renderer.h"
#include "synthetic_runs.h"

namespace kf {
namespace {

namespace fs = std::filesystem;

// A tetrahedron ("head") and a quad ("board"), `frames` frames, moving up 0.1 m per frame.
MeshSequence two_meshes(int frames, double size = 1.0, Vec3 center = Vec3::Zero()) {
  MeshSequence s;
  s.fps = 24.0;
  s.add_mesh("head", 4, {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3});
  s.add_mesh("board", 4, {0, 1, 2, 0, 2, 3});
  for (int f = 0; f < frames; ++f) {
    VecX a(12), b(12);
    const Vec3 up(0, 0.1 * f, 0);
    const Vec3 tet[4] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    const Vec3 quad[4] = {{-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}};
    for (int i = 0; i < 4; ++i) {
      a.segment<3>(3 * i) = center + size * tet[i] + up;
      b.segment<3>(3 * i) = center + size * quad[i] + up;
    }
    s.add_frame({a, b});
  }
  return s;
}

std::string load_error(const fs::path& p) {
  try {
    load_mesh_sequence(p);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(MeshSequence, RoundTripKeepsNamesTopologyAndPositions) {
  render::testing::TempDir tmp;
  const MeshSequence s = two_meshes(3);
  save_mesh_sequence(tmp.path() / "meshes.bin", s);
  const MeshSequence r = load_mesh_sequence(tmp.path() / "meshes.bin");
  ASSERT_EQ(r.meshes.size(), 2u);
  EXPECT_EQ(r.meshes[0].name, "head");
  EXPECT_EQ(r.meshes[1].name, "board");
  EXPECT_EQ(r.meshes[0].triangles, s.meshes[0].triangles);
  EXPECT_EQ(r.meshes[1].triangle_count(), 2);
  EXPECT_EQ(r.frames(), 3);
  EXPECT_DOUBLE_EQ(r.fps, 24.0);
  EXPECT_EQ(r.positions, s.positions);
  EXPECT_FLOAT_EQ(r.vertex_positions(2, 1)[1], 0.2f);  // board vertex 0 y at frame 2
}

TEST(MeshSequence, BuildingRejectsBadInput) {
  MeshSequence s;
  EXPECT_THROW(s.add_mesh("", 3, {0, 1, 2}), std::invalid_argument);
  EXPECT_THROW(s.add_mesh("a", 3, {0, 1, 3}), std::invalid_argument);
  EXPECT_THROW(s.add_mesh("a", 3, {0, 1}), std::invalid_argument);
  s.add_mesh("a", 3, {0, 1, 2});
  EXPECT_THROW(s.add_frame({VecX::Zero(6)}), std::invalid_argument);
  EXPECT_THROW(s.add_frame({VecX::Zero(9), VecX::Zero(9)}), std::invalid_argument);
  s.add_frame({VecX::Zero(9)});
  EXPECT_THROW(s.add_mesh("b", 3, {0, 1, 2}), std::invalid_argument);
}

TEST(MeshSequence, EachDamageHasItsOwnError) {
  render::testing::TempDir tmp;
  const fs::path good = tmp.path() / "good.bin";
  save_mesh_sequence(good, two_meshes(2));
  std::ifstream in(good, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  auto damaged = [&](const std::string& name, std::string b) {
    std::ofstream(tmp.path() / name, std::ios::binary) << b;
    return tmp.path() / name;
  };
  EXPECT_NE(load_error(tmp.path() / "missing.bin").find("cannot open"), std::string::npos);
  std::string b = bytes;
  b[0] = 'X';
  EXPECT_NE(load_error(damaged("magic.bin", b)).find("bad magic"), std::string::npos);
  EXPECT_NE(load_error(damaged("short.bin", bytes.substr(0, bytes.size() - 5))).find("truncated or padded"),
            std::string::npos);
  EXPECT_NE(load_error(damaged("header.bin", bytes.substr(0, 14))).find("truncated"), std::string::npos);
  b = bytes;
  // First index of "head" sits after magic 8, counts 8, fps 8, name length 4, "head" 4, V 4, T 4.
  const uint32_t bad = 99;
  std::memcpy(&b[40], &bad, 4);
  EXPECT_NE(load_error(damaged("index.bin", b)).find("vertex index 99"), std::string::npos);
  EXPECT_EQ(load_error(good), "no error");
}

TEST(MeshSequence, RunWithWrongFrameCountIsRejected) {
  render::testing::TempDir tmp;
  const fs::path run = render::testing::make_cloth_run(tmp.path() / "cloth", 8);
  save_mesh_sequence(run / "meshes.bin", two_meshes(4));  // the run has 6 frames
  try {
    render::load_run(run);
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("meshes.bin has 4 frames but trajectory.bin has 6"), std::string::npos)
        << e.what();
  }
}

// Counts pixels close to the body colour.
int skin_pixels(const render::Image& img, const Vec3& skin) {
  int n = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const uint8_t* p = img.at(x, y);
      // Shading scales the colour: compare hue ratios, not levels.
      const double r = p[0], g = p[1], b = p[2];
      if (r > 40 && std::abs(g / r - skin.y() / skin.x()) < 0.05 && std::abs(b / r - skin.z() / skin.x()) < 0.05) ++n;
    }
  return n;
}

TEST(MeshSequence, BothBackEndsDrawTheBodies) {
  render::testing::TempDir tmp;
  const fs::path run = render::testing::make_cloth_run(tmp.path() / "cloth", 8);
  const Vec3 skin = RenderSpec().body_color;
  for (const char* backend : {"osmesa", "embree"}) {
    const render::RunData without = render::load_run(run);
    render::FrameRenderer plain(without, backend, {96, 72, 2});
    const int before = skin_pixels(plain.render(3), skin);
    save_mesh_sequence(run / "meshes.bin", two_meshes(6, 0.3, Vec3(0.5, 0.2, 0.5)));
    const render::RunData with = render::load_run(run);
    ASSERT_TRUE(with.meshes.has_value());
    render::FrameRenderer body(with, backend, {96, 72, 2});
    const int after = skin_pixels(body.render(3), skin);
    EXPECT_GT(after, before + 50) << backend;
    fs::remove(run / "meshes.bin");
  }
}

}  // namespace
}  // namespace kf
