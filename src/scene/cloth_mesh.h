#pragma once
// A cloth's own mesh (cloth.mesh): its vertices are the particles, its faces give the springs
// (sim/cloth/mesh_springs.h). Read from any file assimp reads; OBJ by our own reader, so vertex i is the
// i-th vertex of the file that a face of the mesh uses (the order Blender and other modellers show).
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "core/types.h"

namespace kf {

struct ClothMesh {
  std::string file;                      // as the scene resolved it (messages)
  std::vector<Vec3> vertices;            // rest positions, metres, in the scene's frame
  std::vector<std::vector<int>> faces;   // polygons (3 or 4 corners; larger ones are fanned), counter-clockwise
  // Named vertex sets the file carries (OBJ: each "g" group's and "o" object's faces' vertices), ascending.
  std::map<std::string, std::vector<int>> groups;

  int particles() const { return int(vertices.size()); }
  // The faces as triangles (quads split along their first diagonal), three indices each.
  std::vector<int> triangles() const;
};

// Refuses files larger than this (bytes) and meshes with more vertices: a mistaken path to a scan.
constexpr std::uintmax_t kMaxClothMeshBytes = std::uintmax_t(1) << 30;
constexpr int kMaxClothMeshVertices = 1 << 20;

// Reads mesh `name` ("" = the file's only mesh) of `file` in the file's own frame. Faces with fewer than 3
// distinct corners are dropped; vertices no face uses are left out. Throws InputError naming the file when it
// is missing, not a regular file, unreadable, too large, or has no such mesh.
ClothMesh read_cloth_mesh(const std::filesystem::path& file, const std::string& name);

}  // namespace kf
