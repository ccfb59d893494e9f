#pragma once
// The animation a run produces, one state per rendered frame, and its file format.
//
// File `trajectory.bin` (little endian): 8-byte magic "KFTRAJ01", uint32 particles p, uint32 frames F
// (states 0..F-1), float64 fps, then for each frame: p*3 float64 positions (metres, world frame, Y up)
// followed by p*3 float64 velocities (m/s).
#include <filesystem>
#include <vector>

#include "core/types.h"

namespace kf {

struct Trajectory {
  int particles = 0;
  double fps = 30.0;
  std::vector<VecX> x;  // per frame, 3p
  std::vector<VecX> v;  // per frame, 3p
  int frames() const { return int(x.size()); }
};

// Writes atomically; throws OutputError.
void save_trajectory(const std::filesystem::path& path, const Trajectory& t);
// Throws InputError naming the file when it is missing, truncated or not a trajectory.
Trajectory load_trajectory(const std::filesystem::path& path);

}  // namespace kf
