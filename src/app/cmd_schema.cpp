// keyframe schema: the scene format as JSON Schema, generated from the keys the scene parser reads
// (scenes/scene.schema.json is its committed copy; scenes name it with "$schema" for editors).
#include <unistd.h>

#include <filesystem>
#include <iostream>

#include "app/commands.h"
#include "core/atomic_file.h"
#include "scene/scene_schema.h"

namespace kf {

void add_schema_command(CLI::App& app) {
  auto* sub = app.add_subcommand("schema", "print the scene format as JSON Schema (draft-07), generated from the "
                                           "keys the scene parser reads");
  auto out = std::make_shared<std::string>();
  sub->add_option("-o,--output", *out, "write it to this file instead of standard output");
  sub->footer(
      "scenes/scene.schema.json is this command's output; a scene names it with\n"
      "  \"$schema\": \"scene.schema.json\"\n"
      "so editors that read JSON Schema check and complete its keys. Example:\n"
      "  keyframe schema -o scenes/scene.schema.json");
  sub->callback([=] {
    // The example scenes the schema is read from need a mesh file and a run on disk.
    namespace fs = std::filesystem;
    const fs::path scratch = fs::temp_directory_path() / ("keyframe_schema_" + std::to_string(::getpid()));
    Json schema;
    try {
      schema = scene_schema(every_branch_logs(scratch));
    } catch (...) {
      fs::remove_all(scratch);
      throw;
    }
    fs::remove_all(scratch);
    const std::string text = schema.dump(2) + "\n";
    if (out->empty()) {
      std::cout << text;
      return;
    }
    write_file_atomic(*out, text);
  });
}

}  // namespace kf
