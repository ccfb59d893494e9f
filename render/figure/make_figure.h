#pragma once
// keyframe figure: render chosen frames of one or more runs into one labelled sheet.
#include <filesystem>
#include <string>
#include <vector>

namespace kf::render {

struct FigureRequest {
  std::vector<std::filesystem::path> run_dirs;  // one row each
  std::vector<int> frames;                      // empty: frame 0, every keyframe, the last frame (at most 6)
  std::string name;                             // output file name without .png; empty: first run's scene
  std::filesystem::path out_dir = "out/figures";
  std::string backend = "osmesa";
  int width = 400, height = 300;                // one tile, pixels
  int spp = 0;                                  // 0: back end default
  bool overlay = false;                         // one superimposed tile per run instead of a strip
};

// Throws InputError (bad request, run or frame; nothing written) or OutputError. Returns the PNG path.
std::filesystem::path make_figure(const FigureRequest& request);

}  // namespace kf::render
