#pragma once
// The scene format as JSON Schema (draft-07), generated from what the parser itself reads.
//
// The parser's Block reads log each key's type, range, default and choices (ParamLog). Parsing example
// scenes that enter every branch (each objective type, collider shape, character block and optimizer stage)
// gives every key; merging their logs gives the schema. `keyframe schema` prints it and
// scenes/scene.schema.json is its committed copy, so editors validate and complete scene files.
//
// The schema is looser than the parser where a rule depends on the scene itself: a bound that changes with
// the scene's size (a keyframe's frame within the scene's frames, particle indices) is left out, as are
// rules between keys (exactly one of "flock" or "cloth"). A file the parser accepts always validates.
#include <filesystem>
#include <vector>

#include "scene/params.h"

namespace kf {

// One log per parse of the example scenes, each parsed at two sizes (frames, agents, cloth resolution) so
// bounds that follow the scene's size can be told apart. The cape's mesh and the runs its start and end
// read are written into `scratch` (created if missing).
std::vector<ParamLog> every_branch_logs(const std::filesystem::path& scratch);

// The JSON Schema of the keys in `logs`: each object lists its keys (no others allowed), each key its type,
// range, default (where every read agrees) and choices; a key is required when every object that holds it
// read it as required.
Json scene_schema(const std::vector<ParamLog>& logs);

}  // namespace kf
