#pragma once
// keyframe export: a run's animated geometry as files other tools read (through assimp's exporters).
#include <filesystem>
#include <string>
#include <vector>

namespace kf::render {

struct ExportRequest {
  std::filesystem::path run_dir;  // holds scene.json, trajectory.bin and maybe meshes.bin
  std::string format = "obj";     // "obj" | "ply" | "gltf2"
  int frame_begin = 0;            // first frame
  int frame_end = -1;             // one past the last, -1: all
};

// The --format names, in the order --help lists them.
std::vector<std::string> export_format_names();

// Writes RUN_DIR/export/frame_NNNN.obj (+ .mtl) or frame_NNNN.ply per frame, or one
// RUN_DIR/export/<scene>.gltf (+ .bin) holding every frame as its own node "frame_NNNN" with the
// frame's meshes. Meshes per frame: "cloth" (the particle grid, shared vertices) or "agents" (the
// rendered arrowheads), plus every mesh of meshes.bin under its own name; metres, Y up.
// Throws InputError for a bad request or run (nothing written), OutputError when writing fails (files
// appear whole or not at all). Returns the files written.
std::vector<std::filesystem::path> export_run(const ExportRequest& request);

}  // namespace kf::render
