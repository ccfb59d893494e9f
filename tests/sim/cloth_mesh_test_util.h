#pragma once
// Cloth meshes for tests (cloth.mesh): OBJ files of a grid and of an irregular patch with a hole.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "scene/cloth_spec.h"
#include "scene/scene.h"

namespace kf::test {

// A fresh directory under the system temp dir, named after the running test, removed when it passed.
class MeshDir {
 public:
  MeshDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::temp_directory_path() / ("keyframe_mesh_" + std::string(info->test_suite_name()) + "_" +
                                                      info->name() + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~MeshDir() {
    if (!::testing::Test::HasFailure()) std::filesystem::remove_all(path_);
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// Writes vertices and faces (0-based corners) as OBJ, coordinates to 17 digits (they read back exactly).
inline void write_obj(const std::filesystem::path& file, const std::vector<Vec3>& vertices,
                      const std::vector<std::vector<int>>& faces) {
  FILE* f = std::fopen(file.c_str(), "w");
  ASSERT_NE(f, nullptr);
  std::fprintf(f, "o Cloth\n");
  for (const Vec3& p : vertices) std::fprintf(f, "v %.17g %.17g %.17g\n", p.x(), p.y(), p.z());
  for (const auto& face : faces) {
    std::fprintf(f, "f");
    for (int v : face) std::fprintf(f, " %d", v + 1);
    std::fprintf(f, "\n");
  }
  std::fclose(f);
}

// The grid of `c` (nx, ny, width, height, origin, u_axis, v_axis) as quads: vertex j nx + i is particle (i, j),
// placed as ClothSystem lays the grid out.
inline std::filesystem::path write_grid_obj(const std::filesystem::path& dir, const ClothSpec& c) {
  std::vector<Vec3> v;
  const double dx = c.width / (c.nx - 1), dy = c.height / (c.ny - 1);
  for (int j = 0; j < c.ny; ++j)
    for (int i = 0; i < c.nx; ++i) v.push_back(c.origin + i * dx * c.u_axis + j * dy * c.v_axis);
  std::vector<std::vector<int>> faces;
  for (int j = 0; j + 1 < c.ny; ++j)
    for (int i = 0; i + 1 < c.nx; ++i)
      faces.push_back({c.index(i, j), c.index(i + 1, j), c.index(i + 1, j + 1), c.index(i, j + 1)});
  const auto file = dir / "grid.obj";
  write_obj(file, v, faces);
  return file;
}

// An irregular patch of side `side` centred on `center` in the x-z plane: a 6 x 6 lattice jittered by up to
// 15 % of its spacing, one interior cell left out (a hole), one corner cell left out (a notch), cells split
// into triangles along alternating diagonals where (i + j) % 3 == 0, quads elsewhere. Vertex ids from `first`.
inline void irregular_patch(const Vec3& center, double side, int first, std::vector<Vec3>& v,
                            std::vector<std::vector<int>>& faces) {
  constexpr int n = 6;
  const double d = side / (n - 1);
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> U(-0.15 * d, 0.15 * d);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      v.push_back(center + Vec3(-0.5 * side + i * d + U(rng), 0, -0.5 * side + j * d + U(rng)));
  auto id = [first](int i, int j) { return first + j * n + i; };
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      if ((i == 2 && j == 2) || (i == n - 2 && j == n - 2)) continue;
      const int a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), e = id(i, j + 1);
      if ((i + j) % 3 != 0) faces.push_back({a, b, c, e});
      else if ((i + j) % 2 == 0) faces.insert(faces.end(), {{a, b, c}, {a, c, e}});
      else faces.insert(faces.end(), {{a, b, e}, {b, c, e}});
    }
}

inline std::filesystem::path write_irregular_obj(const std::filesystem::path& dir, const Vec3& center, double side) {
  std::vector<Vec3> v;
  std::vector<std::vector<int>> faces;
  irregular_patch(center, side, 0, v, faces);
  const auto file = dir / "irregular.obj";
  write_obj(file, v, faces);
  return file;
}

// The irregular patch folded over: a second copy `gap` above the first, shifted by `shift` in the plane,
// joined to it along the patch's j = 0 edge by a strip of quads (the fold), so the mesh is one piece whose
// two layers lie closer than a self-contact thickness above `gap`. 72 vertices.
inline std::filesystem::path write_folded_irregular_obj(const std::filesystem::path& dir, const Vec3& center,
                                                        double side, double gap, const Vec3& shift) {
  std::vector<Vec3> v;
  std::vector<std::vector<int>> faces;
  irregular_patch(center, side, 0, v, faces);
  irregular_patch(center + Vec3(0, gap, 0) + shift, side, 36, v, faces);
  for (int i = 0; i + 1 < 6; ++i) faces.push_back({i, i + 1, 36 + i + 1, 36 + i});
  const auto file = dir / "folded.obj";
  write_obj(file, v, faces);
  return file;
}

// The folded irregular mesh lying on the ground with friction, pinned at one corner region of its lower layer;
// `self` is the scene's cloth.self block.
inline Scene folded_mesh_scene(const std::filesystem::path& dir, const std::filesystem::path& file, const char* controls,
                               int substeps, const std::string& self) {
  return parse_scene(
      std::string(R"({"time": {"fps": 30, "frames": 3, "substeps": )") + std::to_string(substeps) +
          R"(}, "cloth": {"mesh": {"file": ")" + file.string() + R"("}, "mass": 0.1, "solver": "direct",
          "velocity": [0.6, 0, 0.2], "pins": {"min": [-1, -1, -1], "max": [-0.1, 0.015, -0.1]}, "self": )" + self + R"(,
          "colliders": [{"type": "ground", "thickness": 0.015, "stiffness": 3000, "friction": 0.5}]},
          "controls": )" + controls + R"(,
          "objectives": [{"type": "position", "frame": 3, "weight": 100,
                          "particles": {"min": [-1, 0.015, -1], "max": [1, 1, 1]}, "targets": [[0.05, 0.03, 0]]}]})",
      dir / "folded.json");
}

}  // namespace kf::test
