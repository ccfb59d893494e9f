#pragma once
// scene_name.txt of a run directory: line 1 the scene's name (it names exported files and the farm's jobs),
// line 2 the directory of the original scene file (relative assets are found from there).
#include <filesystem>
#include <optional>
#include <string>

namespace kf {

struct RunName {
  std::string name;                 // a safe single file name (core/file_name.h)
  std::filesystem::path directory;  // empty when the file has no second line
};

// Reads DIR/scene_name.txt; nullopt when there is none. Throws InputError naming the file and the line
// when the name could escape the directory it names files in ("..", '/', control characters) or the
// file is not two short lines.
std::optional<RunName> read_run_name(const std::filesystem::path& run_dir);

}  // namespace kf
