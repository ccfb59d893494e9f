#pragma once
// A moving object as Blender and Maya read it: the rest shape as an OBJ whose vertex order is the
// particles' order, and the motion as a point cache (.pc2: Blender's Mesh Cache modifier, Maya's and
// 3ds Max's point cache readers). Metres, Y up (the axes keyframe simulates in).
#include <filesystem>

#include "render/export/animated_gltf.h"

namespace kf::render {

// OBJ of frame 0 of `mesh`: "o NAME", one "v" per vertex in order, one "f" per triangle.
void write_rest_obj(const std::filesystem::path& path, const MovingMesh& mesh);

// PC2: the 12-byte signature "POINTCACHE2\0", version 1, point count, start frame, sample rate 1 (a
// sample per frame), sample count, then every sample's points as float32 x, y, z (little-endian).
void write_pc2(const std::filesystem::path& path, const MovingMesh& mesh, int start_frame);

}  // namespace kf::render
