#pragma once
// keyframe export: a run's animated geometry as files other tools read (through assimp's exporters).
#include <filesystem>
#include <string>
#include <vector>

namespace kf::render {

struct ExportRequest {
  std::filesystem::path run_dir;  // holds scene.json, trajectory.bin and maybe meshes.bin
  std::string format = "gltf2";   // "gltf2" | "pc2" | "obj" | "ply"
  int frame_begin = 0;            // first frame
  int frame_end = -1;             // one past the last, -1: all
};

// The --format names, in the order --help lists them.
std::vector<std::string> export_format_names();

// Writes into RUN_DIR/export/. The objects: "cloth" (the particle grid) or "agents" (the rendered
// arrowheads), plus every mesh of meshes.bin under its own name ("body"); metres, Y up.
//   gltf2: <scene>.gltf + <scene>.bin, one animated file (animated_gltf.h);
//   pc2:   NAME.obj (the first frame, vertices in particle order) + NAME.pc2 (the motion) per object;
//   obj, ply: frame_NNNN.obj (+ .mtl) or frame_NNNN.ply per frame, each object its own node.
// Throws InputError for a bad request or run (nothing written), OutputError when writing fails (files
// appear whole or not at all). Returns the files written.
std::vector<std::filesystem::path> export_run(const ExportRequest& request);

}  // namespace kf::render
