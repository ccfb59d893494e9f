#pragma once
// Synthetic run directories for renderer tests: agents on circles, a cloth sheet waving with a sine.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include <gtest/gtest.h>

#include "core/trajectory.h"

namespace kf::render::testing {

namespace fs = std::filesystem;

// A fresh directory under the system temp dir, named after the running test, removed at exit.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() /
            ("keyframe_" + std::string(info->test_suite_name()) + "_" + info->name() + "_" + std::to_string(::getpid()));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    if (!::testing::Test::HasFailure()) fs::remove_all(path_);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

inline void write_text(const fs::path& p, const std::string& s) { std::ofstream(p) << s; }

// 40 agents circling the origin (radii 2..8 m), a square and a cross keyframe, a path and a race.
inline fs::path make_flock_run(const fs::path& dir, const std::string& render_block = "{}") {
  fs::create_directories(dir);
  const int p = 40, frames = 6;
  write_text(dir / "scene.json", R"({"time": {"frames": 5}, "flock": {"agents": 40}, "render": )" + render_block + R"(,
    "objectives": [
      {"type": "shape", "frame": 3, "polygon": [[-5,-5],[5,-5],[5,5],[-5,5]]},
      {"type": "shape", "frame": 5, "polygon": [[-2,-7],[2,-7],[2,-2],[7,-2],[7,2],[2,2],[2,7],[-2,7],[-2,2],[-7,2],[-7,-2],[-2,-2]]},
      {"type": "position", "frame": 5, "particles": [3], "targets": [[8, 0, 0]]},
      {"type": "center_of_mass", "frame": 2, "target": [3, 0, 3]},
      {"type": "center_of_mass", "frame": 5, "target": [6, 0, -2]}]})");
  write_text(dir / "scene_name.txt", "flock\n");
  Trajectory t;
  t.particles = p;
  for (int f = 0; f < frames; ++f) {
    VecX x(3 * p), v(3 * p);
    for (int i = 0; i < p; ++i) {
      const double r = 2.0 + 6.0 * ((i * 17) % p) / p, w = 0.4, a = i * 2.4 + w * f;
      x.segment<3>(3 * i) = Vec3(r * std::cos(a), 0.0, r * std::sin(a));
      v.segment<3>(3 * i) = Vec3(-r * w * std::sin(a), 0.0, r * w * std::cos(a));
    }
    t.x.push_back(x);
    t.v.push_back(v);
  }
  save_trajectory(dir / "trajectory.bin", t);
  return dir;
}

// A 1.5 m square sheet of nx x nx particles about 1 m up, waving with a sine.
inline fs::path make_cloth_run(const fs::path& dir, int nx = 16, const std::string& render_block = "{}") {
  fs::create_directories(dir);
  const int frames = 6;
  write_text(dir / "scene.json", R"({"time": {"frames": 5}, "cloth": {"nx": )" + std::to_string(nx) +
                                     R"(, "ny": )" + std::to_string(nx) + R"(}, "render": )" + render_block +
                                     R"(, "objectives": []})");
  write_text(dir / "scene_name.txt", "cloth\n");
  Trajectory t;
  t.particles = nx * nx;
  for (int f = 0; f < frames; ++f) {
    VecX x(3 * t.particles), v = VecX::Zero(3 * t.particles);
    for (int j = 0; j < nx; ++j)
      for (int i = 0; i < nx; ++i) {
        const double u = double(i) / (nx - 1), w = double(j) / (nx - 1);
        x.segment<3>(3 * (j * nx + i)) =
            Vec3(1.5 * u - 0.75, 1.0 + 0.15 * std::sin(6 * u + 0.5 * f) * std::cos(3 * w), 1.5 * w - 0.75);
      }
    t.x.push_back(x);
    t.v.push_back(v);
  }
  save_trajectory(dir / "trajectory.bin", t);
  return dir;
}

}  // namespace kf::render::testing
