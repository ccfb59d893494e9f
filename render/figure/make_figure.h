#pragma once
// keyframe figure: render chosen frames of one or more runs into one labelled sheet.
#include <filesystem>
#include <string>
#include <vector>

namespace kf::render {

// Frame numbers that stand for a frame of each run (runs may have different lengths and keyframes).
constexpr int kLastKeyframe = -1;  // the run's last keyframe (its last frame if it has none)
constexpr int kLastFrame = -2;     // the run's last frame

// Paper-style sheets: fig. 1 = runs side by side at their last keyframe (`--columns --frames key`),
// fig. 2/4/5 = strips over time (rows), fig. 3 = `--overlay`, fig. 6 = three runs as columns, time going
// down (`--columns --frames 0,15,last`).
struct FigureRequest {
  std::vector<std::filesystem::path> run_dirs;  // one row each (one column each with `columns`)
  std::vector<int> frames;                      // empty: frame 0, every keyframe, the last frame (at most 6);
                                                // may hold kLastKeyframe / kLastFrame
  bool columns = false;                         // runs side by side, frames going down
  std::string name;                             // output file name without .png/.pdf; empty: first run's scene
  std::string title;                            // set above the sheet; empty: the first run's scene name
  std::string caption;                          // set under the sheet (e.g. the paper's caption); may be empty
  std::vector<std::string> labels;              // one per run, naming its row (column); empty: each run's
                                                // scene name (runs of one scene then need labels)
  std::filesystem::path out_dir = "out/figures";
  std::string backend = "osmesa";
  int width = 400, height = 300;                // one tile, pixels
  int spp = 0;                                  // 0: back end default
  bool overlay = false;                         // one tile per run instead of a strip: a flock's path
                                                // (add_flock_path), other runs' frames superimposed
};

// Writes out_dir/NAME.png and, with the same layout and vector type, out_dir/NAME.pdf. Throws InputError
// (bad request, run or frame; nothing written) or OutputError. Returns the PNG path.
std::filesystem::path make_figure(const FigureRequest& request);

}  // namespace kf::render
