// keyframe inspect FILE: what a mesh or character file holds (the names and numbers a scene's "character"
// block needs), or a scene with every default filled in.
#include <iostream>

#include "app/commands.h"
#include "core/error.h"
#include "core/file_name.h"
#include "report/shape_summary.h"
#include "scene/params.h"
#include "scene/scene.h"
#include "sim/character/asset_summary.h"

namespace kf {

namespace {

void inspect(const std::string& file, bool json) {
  const std::filesystem::path path(file);
  if (path.extension() == ".json") {
    ParamLog log;
    const Scene scene = load_scene(path, &log);
    std::cout << log.resolved.dump(2) << "\n";
    if (json) return;
    // Each shape as it lies on the ground: a mirrored or misplaced drawing shows in its bounds and area.
    for (const ShapeSummary& s : shape_summaries(scene)) std::cout << shape_summary_line(s) << "\n";
    return;
  }
  const AssetSummary s = summarize_asset(path);
  if (json)
    std::cout << asset_json(s).dump(2) << "\n";
  else
    std::cout << asset_text(s);
}

}  // namespace

void add_inspect_command(CLI::App& app) {
  auto* sub = app.add_subcommand(
      "inspect", "show what a mesh or character file holds (meshes, bones and nodes, animations, bounds, units), "
                 "or a scene file with every default filled in");
  auto file = std::make_shared<std::string>();
  auto json = std::make_shared<bool>(false);
  sub->add_option("FILE", *file, "any file assimp reads (.X, .fbx, .dae, .gltf, .obj, .bvh, ...) or a scene (.json)")
      ->required();
  sub->add_flag("--json", *json, "print JSON (for scripts) instead of text");
  sub->footer(
      "A scene (.json) is printed as JSON: the file as keyframe reads it, every key it leaves out filled in\n"
      "with its default; then (without --json) one line per flock shape keyframe: its bounds on the ground,\n"
      "its area less its holes, and how many agents it holds at the avoidance radius apart (packed\n"
      "hexagonally) against the flock's count. Examples:\n"
      "  keyframe inspect /usr/share/assimp/models/X/Testwuson.X\n"
      "  keyframe inspect scenes/square.json");
  sub->callback([=] {
    try {
      inspect(*file, *json);
    } catch (const InputError& e) {
      throw InputError(printable(e.what()));  // one line, whatever the file's name or contents hold
    }
  });
}

}  // namespace kf
