#pragma once
// One animated glTF 2.0 file for a run: each moving object (the cloth, the agents, the body) is one node
// with one mesh, and its motion is a set of morph targets, one per frame, whose weights the animation
// "keyframe" switches from frame to frame (linear blends between neighbouring frames). Metres, Y up, as
// glTF wants; a glTF viewer or Blender's importer plays it as is.
#include <filesystem>
#include <string>
#include <vector>

#include "core/types.h"

namespace kf::render {

// An object whose triangles stay the same while its vertices move: positions and normals per frame.
struct MovingMesh {
  std::string name;
  Vec3 color;
  std::vector<uint32_t> indices;              // 3T
  std::vector<std::vector<float>> positions;  // per frame: 3V
  std::vector<std::vector<float>> normals;    // per frame: 3V, unit
  std::string vertices;                       // what the vertices are (for file headers), e.g. "vertex i is particle i"
};

// Writes `gltf` (JSON) and `bin` beside it (the buffer, named by its file name in the JSON). Frame k of
// every object is shown at time k / fps. Throws OutputError when a file cannot be written.
void write_animated_gltf(const std::filesystem::path& gltf, const std::filesystem::path& bin,
                         const std::vector<MovingMesh>& objects, double fps);

}  // namespace kf::render
