#pragma once
// What a mesh or character file holds, as assimp reads it for keyframe (the same import steps as
// Character): meshes with their sizes and bounds, the node and bone hierarchy, the animations with their
// durations, and the units and up axis the file states. For `keyframe inspect FILE`: the names a scene's
// "character" block refers to (anchors by mesh, bone or node) and the numbers it needs (the animation's
// length, the body's height).
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/types.h"

namespace kf {

struct AssetMesh {
  std::string name;
  int vertices = 0, triangles = 0;  // after joining identical vertices and triangulating
  int bones = 0;                    // bones that weight this mesh's vertices
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();  // box of the bind pose as a character is posed (Character::
                                              // bind_vertices), the file's frame and units
};

struct AssetNode {
  std::string name;
  int parent = -1;  // index into AssetSummary::nodes; -1 for the root
  int depth = 0;
  bool bone = false;      // some mesh's vertices follow it
  bool animated = false;  // some animation has a channel for it
  int meshes = 0;         // meshes attached to this node
  Vec3 position = Vec3::Zero();  // in the bind pose (a bone's, from its offset matrix), the file's frame
};

struct AssetAnimation {
  std::string name;
  double ticks = 0, ticks_per_second = 0, seconds = 0;  // ticks_per_second 0 in the file reads as 25
  int channels = 0;
};

struct AssetSummary {
  std::string file;
  std::vector<AssetMesh> meshes;
  std::vector<AssetNode> nodes;  // parents first
  std::vector<AssetAnimation> animations;
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();  // all meshes
  // What the file states (empty when it says nothing; keyframe then reads coordinates as metres, Y up).
  std::string up_axis;
  double unit_scale = 0;  // metres per file unit, 0 when not stated
};

// Reads `file` with assimp. Throws InputError naming the file when it is missing or unreadable.
AssetSummary summarize_asset(const std::filesystem::path& file);

nlohmann::json asset_json(const AssetSummary& s);
// A few lines a reader can scan: meshes, animations, then the hierarchy (bones marked).
std::string asset_text(const AssetSummary& s);

}  // namespace kf
