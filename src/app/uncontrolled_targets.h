#pragma once
// Keyframe targets stated as an offset from where the particles would be without controls (a position
// keyframe's or a centre of mass's "offset" with "from": "uncontrolled": "lift this edge 30 cm above where it
// would hang"). The scene layer cannot simulate, so its parser keeps the offsets as the targets; a job
// (optimize, simulate, gradcheck) makes them absolute with one forward simulation without controls.
#include <nlohmann/json.hpp>

#include "scene/scene.h"

namespace kf {

// The scene file's objectives (indices into Scene::objectives) whose targets are offsets from the
// uncontrolled motion. `scene_json`: the file as parsed into `scene`.
std::vector<int> offsets_from_uncontrolled(const nlohmann::json& scene_json, const Scene& scene);

// Reads the scene's file again for the objectives that ask and, when any does, runs the scene once without
// controls and replaces their offsets by the particles' positions at each one's frame plus the offset (a
// centre of mass: their mean plus the offset). Call once per loaded scene. Throws InputError when that
// simulation diverges.
void resolve_uncontrolled_offsets(Scene& scene);

// A resolved scene's targets written into the scene file's JSON: each objective that asked has its "offset"
// and "from" replaced by the absolute "targets" (or "target"), so a run directory's scene.json reads back
// the same targets (render, resume) without simulating again.
void write_resolved_targets(nlohmann::json& scene_json, const Scene& scene);

}  // namespace kf
