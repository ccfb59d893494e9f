#pragma once
// The run directory: out/<scene>/ with the scene copy, trajectory, logs, report and frames.
#include <filesystem>
#include <nlohmann/json.hpp>

#include "scene/scene.h"

namespace kf {

// out/<scene name>/ unless --out was given.
std::filesystem::path run_dir_for(const Scene& scene, const std::string& out_option);
// Creates the directory and stores a copy of the scene file as scene.json (atomically).
void prepare_run_dir(const std::filesystem::path& dir, const Scene& scene);
// Names a scene's relative asset paths (a character's mesh, a cape's start and target runs) absolutely from
// `scene_dir`, so that a copy of the scene JSON reads the same from any directory.
void absolutise_scene_paths(nlohmann::json& scene, const std::filesystem::path& scene_dir);
// Loads the scene copy a run directory holds. Throws InputError if it is not a run directory.
Scene load_run_scene(const std::filesystem::path& dir);
// Writes JSON atomically, pretty-printed.
void write_json(const std::filesystem::path& path, const nlohmann::json& j);

}  // namespace kf
