#pragma once
// The scene file's cloth.mesh block and particle regions (pins, keyframe particle sets):
//   "mesh": {"file": "../assets/cloth/flag.obj",   // relative to the scene file's directory
//            "name": "Flag",                        // the object, group or mesh within the file ("": the only one)
//            "scale": 1,                            // file units to metres
//            "up_axis": "y",                        // "z": the file is Z-up (Blender): (x, y, z) -> (x, z, -y)
//            "rotation": {"axis": [0, 1, 0], "degrees": 0},  // then about the origin
//            "offset": [0, 0, 0]}                   // then moved, metres
//   a region: {"min": [x, y, z], "max": [x, y, z]}  // the particles whose rest position lies in the box
//   a named set: {"group": "collar"}                // a mesh cloth's vertices the file names (OBJ "g" or "o")
#include <filesystem>
#include <memory>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/types.h"
#include "scene/cloth_mesh.h"

namespace kf {
class Block;
struct ClothSpec;

// Reads the block, the file and applies the transform (every vertex within 1e6 m of the origin).
std::shared_ptr<const ClothMesh> parse_cloth_mesh(Block b, const std::filesystem::path& directory);

// A particle's rest position before any imperfection: the mesh's vertex, or its place on the grid.
Vec3 cloth_rest_position(const ClothSpec& c, int particle);

// Whether a particle set is a box of rest space ({"min", "max"}) rather than a selector (particle_selector.h).
bool is_rest_box(const nlohmann::json& set);

// The particles (ascending) whose rest position lies in the block's box; at least one, or the block fails.
std::vector<int> particles_in_region(Block& b, const ClothSpec& c);

// Whether a particle set names one of the mesh file's vertex sets ({"group": NAME}).
bool is_group_set(const nlohmann::json& set);

// The particles (ascending) of the block's named set; the block fails naming the sets the file has.
std::vector<int> particles_in_group(Block& b, const ClothSpec& c);

}  // namespace kf
