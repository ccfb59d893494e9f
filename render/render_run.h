#pragma once
// Renders the trajectory of a run directory into frames/frame_%04d.png.
#include <filesystem>
#include <string>

namespace kf::render {

struct RenderRequest {
  std::filesystem::path run_dir;   // holds scene.json and trajectory.bin
  std::string backend = "osmesa";  // "osmesa" | "embree"
  int width = 0, height = 0;       // 0: the scene's render settings
  int spp = 0;                     // samples per pixel, 0: back end default
  int frame_begin = 0;             // first frame to render
  int frame_end = -1;              // one past the last, -1: all
  int turntable = 0;               // >0: this many frames orbiting frame_begin instead
};

// Throws InputError for a bad request or run directory (before writing anything), OutputError when
// a frame cannot be written. Returns the number of frames written.
int render_run(const RenderRequest& request);

}  // namespace kf::render
