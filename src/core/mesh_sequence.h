#pragma once
// Animated triangle meshes beside a run's particles (e.g. the character a cape hangs on), and their file.
//
// File `meshes.bin` in a run directory (little endian): 8-byte magic "KFMESH01", uint32 mesh count M,
// uint32 frame count F, float64 fps; then per mesh: uint32 name length, the name's bytes (UTF-8),
// uint32 vertex count V, uint32 triangle count T, 3T uint32 vertex indices (counter-clockwise seen from
// outside); then per frame, per mesh in order: 3V float32 positions (metres, world frame, Y up).
// Frame k of meshes.bin belongs with frame k of trajectory.bin; the topology is stored once.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "core/types.h"

namespace kf {

// One named mesh: its triangles; its vertex positions live per frame in MeshSequence.
struct SequenceMesh {
  std::string name;                // non-empty, at most 255 bytes
  int vertices = 0;                // V
  std::vector<uint32_t> triangles;  // 3T indices in [0, V)
  int triangle_count() const { return int(triangles.size() / 3); }
};

struct MeshSequence {
  double fps = 30.0;
  std::vector<SequenceMesh> meshes;
  // Per frame, all meshes' positions one after another: 3 * (V_0 + V_1 + ...) floats, metres.
  std::vector<std::vector<float>> positions;

  int frames() const { return int(positions.size()); }
  int total_vertices() const;
  // Adds a mesh before any frame was added. `triangles`: 3T indices in [0, vertices). Returns its index.
  // Throws std::invalid_argument on a bad name or index, or when frames exist already.
  int add_mesh(const std::string& name, int vertices, std::vector<uint32_t> triangles);
  // Appends a frame: `x[m]` holds 3V_m positions of mesh m (metres). Throws std::invalid_argument on
  // a count or size mismatch.
  void add_frame(const std::vector<VecX>& x);
  // 3V_m floats: mesh `mesh`'s positions at `frame`.
  const float* vertex_positions(int frame, int mesh) const;
};

// Writes atomically (whole or not at all); throws OutputError.
void save_mesh_sequence(const std::filesystem::path& path, const MeshSequence& seq);
// Throws InputError naming the file and what is wrong (missing, bad magic, truncated, index out of range).
MeshSequence load_mesh_sequence(const std::filesystem::path& path);

}  // namespace kf
