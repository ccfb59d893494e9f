#pragma once
// `keyframe optimize`: optimise a scene's controls and write the run directory.
#include <filesystem>
#include <string>

namespace kf {

struct OptimizeOptions {
  std::string out;            // run directory ("" = out/<scene>/)
  int max_evaluations = -1;   // override the scene's limit when >= 0
  bool quiet = false;         // no per-evaluation lines on stdout
  int checkpoint_every = -1;  // override the scene's optimizer.checkpoint_every when >= 0
};

// Returns the run directory. Throws InputError/OutputError.
std::filesystem::path optimize_job(const std::filesystem::path& scene_file, const OptimizeOptions& options);

}  // namespace kf
