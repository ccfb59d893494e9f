#pragma once
// The parts of an assimp scene keyframe reads (nodes, triangle meshes with bones, animations, the file's
// metadata), as bytes: what the child process that imports an untrusted file sends back to its parent.
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>

struct aiScene;

namespace kf {

// Bytes that do not decode (cut short, counts beyond what the bytes hold, indices out of range).
struct MeshWireError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Faces of fewer than 3 corners (points, lines) are left out, polygons kept; metadata keeps booleans, integers, reals and strings.
std::string scene_to_bytes(const aiScene& scene);

// A scene owned by the caller, every index checked against its array (faces, bone weights, node meshes,
// parents before children). Throws MeshWireError.
std::unique_ptr<aiScene> scene_from_bytes(std::string_view bytes);

}  // namespace kf
