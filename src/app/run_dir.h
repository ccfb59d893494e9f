#pragma once
// The run directory: out/<scene>/ with the scene copy, trajectory, logs, report and frames.
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>

#include "core/staged_dir.h"

#include "scene/scene.h"

namespace kf {

// out/<scene name>/ unless --out was given. Throws InputError when --out or the scene's directory holds a
// control character, or (without --out) the scene's name cannot name a directory ("..", a newline).
std::filesystem::path run_dir_for(const Scene& scene, const std::string& out_option);
// Calls `fill(staging directory)`, then swaps the staging directory in place of the run directory; errors
// name the run directory, not its staging copy. Nothing of the new run is kept when `fill` throws.
void commit_run_dir(StagedDir& staged, const std::function<void(const std::filesystem::path& dir)>& fill);
// Calls `step` (which writes into the staging directory); its errors name the run directory instead.
void naming_run_dir(const StagedDir& staged, const std::function<void()>& step);
// Creates the directory and stores a copy of the scene file as scene.json (atomically).
void prepare_run_dir(const std::filesystem::path& dir, const Scene& scene);
// Names a scene's relative asset paths (a character's mesh, a cape's start and target runs, a shape's SVG file)
// absolutely from `scene_dir`, so that a copy of the scene JSON reads the same from any directory.
void absolutise_scene_paths(nlohmann::json& scene, const std::filesystem::path& scene_dir);
// Loads the scene copy a run directory holds (named by its scene_name.txt). Throws InputError if it is not a
// run directory or its scene_name.txt is not a safe name.
Scene load_run_scene(const std::filesystem::path& dir);
// Writes JSON atomically, pretty-printed.
void write_json(const std::filesystem::path& path, const nlohmann::json& j);

}  // namespace kf
