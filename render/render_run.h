#pragma once
// Renders the trajectory of a run directory into frames/frame_%04d.png.
#include <filesystem>
#include <string>

#include "render/camera_choice.h"

namespace kf::render {

struct RenderRequest {
  std::filesystem::path run_dir;   // holds scene.json and trajectory.bin
  std::string backend = "osmesa";  // "osmesa" | "embree"
  int width = 0, height = 0;       // 0: the scene's render settings
  int spp = 0;                     // samples per pixel, 0: back end default
  int frame_begin = 0;             // first frame to render
  int frame_end = -1;              // one past the last, -1: all
  int turntable = 0;               // >0: this many frames orbiting frame_begin instead
  int view_begin = 0, view_end = -1;  // with turntable: render views view_begin..view_end-1 only (-1: all)
  CameraChoice camera;             // --camera / --view (empty: the scene's camera or the automatic one)
};

// Throws InputError for a request out of range (backend, size, samples, turntable); reads no files.
void check_request(const RenderRequest& request);

// Throws InputError for a bad request or run directory (before writing anything), OutputError when
// a frame cannot be written. Returns the number of frames written.
int render_run(const RenderRequest& request);

}  // namespace kf::render
