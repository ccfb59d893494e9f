#pragma once
// A validated scene: the particle system, its keyframes, controls, optimiser settings and look.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/check.h"
#include "scene/character_spec.h"
#include "scene/cloth_spec.h"
#include "scene/flock_spec.h"
#include "scene/objective_spec.h"
#include "scene/render_spec.h"
#include "scene/time_spec.h"

namespace kf {

struct Scene {
  std::string name;                 // file name without .json
  std::filesystem::path file;       // as given
  std::filesystem::path directory;  // where relative asset paths start
  unsigned seed = 1;
  TimeSpec time;
  std::optional<FlockSpec> flock;  // exactly one of flock, cloth
  std::optional<ClothSpec> cloth;
  std::vector<ObjectiveSpec> objectives;
  ControlSpec controls;
  OptimizerSpec optimizer;
  RenderSpec render;
  std::optional<CharacterSpec> character;  // a cape's character (cloth scenes only)
  int particles() const;
};

// Calls f with the scene's particle system, its FlockSpec or its ClothSpec (a cape is a cloth with a
// character), and returns what f returns. This is the one place that knows which member holds the
// system: sites that treat the kinds differently visit with Overloaded{...} (core/overloaded.h), so a new
// kind (a member above and a branch here) is a compile error at each of them until it is handled.
template <class F>
decltype(auto) visit_system(const Scene& scene, F&& f) {
  CHECK(scene.flock.has_value() != scene.cloth.has_value());
  if (scene.flock) return f(*scene.flock);
  return f(*scene.cloth);
}

struct ParamLog;

// Loads and validates a scene file. Throws InputError with "file: /pointer: expected ..." on any problem.
// `log`, when given, receives every key read and the scene with its defaults filled in (keyframe inspect).
Scene load_scene(const std::filesystem::path& file, ParamLog* log = nullptr);
// The same from JSON text already in memory (used by tests and the fuzzer); `file` names it in messages.
Scene parse_scene(const std::string& text, const std::filesystem::path& file, ParamLog* log = nullptr);

// The scene cut to its first `frames` frames (unchanged when frames <= 0 or not fewer than it has), its
// keyframes moved proportionally (gradient checks and benchmarks of long scenes).
Scene shortened(Scene scene, int frames);

}  // namespace kf
