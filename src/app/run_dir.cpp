#include "app/run_dir.h"

#include <fstream>
#include <sstream>

#include "app/uncontrolled_targets.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/file_name.h"
#include "scene/run_name.h"

namespace kf {
namespace fs = std::filesystem;

fs::path run_dir_for(const Scene& scene, const std::string& out_option) {
  if (has_control_character(out_option))
    throw InputError("--out: contains a control character, got \"" + printable(out_option) + "\"");
  const std::string scene_dir = fs::absolute(scene.directory.empty() ? fs::path(".") : scene.directory).string();
  if (has_control_character(scene_dir))
    throw InputError(scene.file.string() + ": the scene's directory contains a control character, got \"" +
                     printable(scene_dir) + "\"");
  if (!out_option.empty()) return fs::path(out_option);
  if (const std::string why = file_name_problem(scene.name); !why.empty())
    throw InputError(scene.file.string() + ": the file's name " + why + ", so it cannot name the run directory " +
                     "(got \"" + printable(scene.name) + "\"); rename the file or pass --out");
  return fs::path("out") / scene.name;
}

void naming_run_dir(const StagedDir& staged, const std::function<void()>& step) {
  try {
    step();
  } catch (const OutputError& e) {
    throw OutputError(staged.public_message(e.what()));
  } catch (const InputError& e) {
    throw InputError(staged.public_message(e.what()));
  }
}

void commit_run_dir(StagedDir& staged, const std::function<void(const fs::path& dir)>& fill) {
  naming_run_dir(staged, [&] {
    fill(staged.path());
    staged.commit();
  });
}

void prepare_run_dir(const fs::path& dir, const Scene& scene) {
  ensure_directory(dir);
  std::ifstream in(scene.file, std::ios::binary);
  std::ostringstream os;
  os << in.rdbuf();
  // Keep the scene's name: the copy is read back with the run directory's scene name.
  auto j = nlohmann::json::parse(os.str());
  // The copy names assets absolutely so it reads the same from the run directory (render, resume).
  absolutise_scene_paths(j, scene.directory);
  write_resolved_targets(j, scene);
  write_file_atomic(dir / "scene.json", j.dump(2) + "\n");
  write_file_atomic(dir / "scene_name.txt", scene.name + "\n" + fs::absolute(scene.directory.empty() ? fs::path(".") : scene.directory).string() + "\n");
}

void absolutise_scene_paths(nlohmann::json& j, const fs::path& scene_dir) {
  // A character's mesh, a cape's start and target runs and SVG files are named relative to the scene's directory.
  const fs::path base = fs::absolute(scene_dir.empty() ? fs::path(".") : scene_dir);
  auto absolutise = [&](nlohmann::json& parent, const char* key) {
    if (parent.is_object() && parent.contains(key) && parent[key].is_string())
      parent[key] = (base / parent[key].get<std::string>()).lexically_normal().string();
  };
  if (j.contains("character") && j["character"].is_object()) {
    auto& c = j["character"];
    absolutise(c, "file");
    if (c.contains("start")) absolutise(c["start"], "run");
    if (c.contains("end_target")) absolutise(c["end_target"], "run");
  }
  // A cloth's mesh file.
  if (j.contains("cloth") && j["cloth"].is_object() && j["cloth"].contains("mesh")) absolutise(j["cloth"]["mesh"], "file");
  // And a shape keyframe's SVG file.
  if (j.contains("objectives") && j["objectives"].is_array())
    for (auto& o : j["objectives"])
      if (o.is_object() && o.contains("svg_path")) absolutise(o["svg_path"], "file");
}

Scene load_run_scene(const fs::path& dir) {
  if (!fs::is_directory(dir)) throw InputError(dir.string() + ": not a run directory (does not exist)");
  const fs::path file = dir / "scene.json";
  if (!fs::exists(file)) throw InputError(dir.string() + ": not a run directory (no scene.json)");
  Scene s = load_scene(file);
  if (const auto names = read_run_name(dir)) {
    s.name = names->name;
    if (!names->directory.empty()) s.directory = names->directory;
  }
  return s;
}

void write_json(const fs::path& path, const nlohmann::json& j) { write_file_atomic(path, j.dump(2) + "\n"); }

}  // namespace kf
