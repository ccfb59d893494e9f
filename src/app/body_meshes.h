#pragma once
// The animated character of a scene, posed at every frame, written as meshes.bin for the renderer.
#include <filesystem>

#include "scene/scene.h"

namespace kf {

// Does nothing for scenes without a character. Throws OutputError when the file cannot be written.
void write_body_meshes(const Scene& scene, int frames, const std::filesystem::path& path);

}  // namespace kf
