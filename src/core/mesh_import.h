#pragma once
// Reading an untrusted mesh file (any format assimp reads) without letting it take keyframe down.
//
// assimp runs in a child process (fork) that sends the scene back through a pipe: its crashes, assertions
// and hangs end the child, and become one InputError naming the file. Every file the import opens (the
// file itself, a glTF's buffers, a material's textures) must be a regular file under kMaxMeshFileBytes,
// and every vertex, node transform, bone offset and animation key must be finite (checked as assimp read
// it, before post-processing, and again on the scene received). In core/ so that the scene layer (a cloth's
// own mesh, cloth.mesh) and the simulation (characters, `inspect`) read every non-OBJ mesh through it.
#include <cstdint>
#include <filesystem>
#include <memory>

struct aiScene;

namespace kf {

inline constexpr std::uintmax_t kMaxMeshFileBytes = std::uintmax_t(1) << 30;  // each file the import opens
inline constexpr unsigned kMeshImportSeconds = 300;  // the child is killed after this long

struct MeshImportOptions {
  unsigned steps = 0;         // assimp post-processing flags (aiProcess_...)
  int max_bone_weights = 4;   // AI_CONFIG_PP_LBW_MAX_WEIGHTS, for aiProcess_LimitBoneWeights
  bool isolated = true;       // false: import in this process (only for measuring what isolation costs)
  unsigned seconds = kMeshImportSeconds;  // the isolated import's time limit
};

// The scene as assimp read it (points and lines dropped; see mesh_wire.h), with its
// AI_SCENE_FLAGS_INCOMPLETE flag as assimp set it. Throws InputError "FILE: ..." when the file is not a
// regular file under the cap, assimp refuses or crashes on it, it opens another file that is not regular
// or too large, or it holds a non-finite value.
std::unique_ptr<aiScene> import_mesh_file(const std::filesystem::path& file, const MeshImportOptions& options);

}  // namespace kf
