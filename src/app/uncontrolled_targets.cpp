#include "app/uncontrolled_targets.h"

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "adjoint/rollout.h"
#include "core/check.h"
#include "core/error.h"
#include "core/overloaded.h"
#include "core/trajectory.h"
#include "sim/make_system.h"

namespace kf {

namespace {

// The particles an objective names, in order (all when it names none).
std::vector<int> named_particles(const ObjectiveSpec& o, int particles) {
  if (!o.particles.empty()) return o.particles;
  std::vector<int> all(static_cast<size_t>(particles));
  for (int i = 0; i < particles; ++i) all[size_t(i)] = i;
  return all;
}

Vec3 position(const Trajectory& t, int frame, int i) { return t.x[size_t(frame)].segment<3>(3 * i); }

[[noreturn]] void no_offset() {
  CHECK(false && "only position and centre-of-mass keyframes take an offset");
  std::abort();
}

void add_uncontrolled(ObjectiveSpec& o, const Trajectory& t) {
  const std::vector<int> set = named_particles(o, t.particles);
  std::visit(Overloaded{[&](PositionKeyframe& k) {
                          std::vector<Vec3> targets;
                          for (size_t m = 0; m < set.size(); ++m)
                            targets.push_back(position(t, o.frame, set[m]) + k.targets[k.targets.size() == 1 ? 0 : m]);
                          k.targets = std::move(targets);
                        },
                        [&](CenterOfMassKeyframe& k) {
                          Vec3 mean = Vec3::Zero();
                          for (int i : set) mean += position(t, o.frame, i) / double(set.size());
                          k.target += mean;
                        },
                        [](auto&) { no_offset(); }},
             o.kind);
}

nlohmann::json json_point(const Vec3& p) { return nlohmann::json::array({p.x(), p.y(), p.z()}); }

// Whether an objective's JSON asks for its offset from the uncontrolled motion (the parser has refused any
// other "from" than "rest" and "uncontrolled").
bool asks(const nlohmann::json& objective) {
  if (!objective.is_object() || !objective.contains("offset")) return false;
  const auto from = objective.find("from");
  return from != objective.end() && from->is_string() && from->get<std::string>() == "uncontrolled";
}

}  // namespace

std::vector<int> offsets_from_uncontrolled(const nlohmann::json& scene_json, const Scene& scene) {
  std::vector<int> marked;
  if (!scene_json.contains("objectives") || !scene_json.at("objectives").is_array()) return marked;
  // The file's objectives in order among the scene's (a character's end target adds objectives it lacks).
  std::vector<int> from_file;
  for (size_t k = 0; k < scene.objectives.size(); ++k)
    if (scene.objectives[k].source == ObjectiveSource::kScene) from_file.push_back(int(k));
  const nlohmann::json& objectives = scene_json.at("objectives");
  CHECK_EQ(objectives.size(), from_file.size());
  for (size_t n = 0; n < objectives.size(); ++n)
    if (asks(objectives[n])) marked.push_back(from_file[n]);
  return marked;
}

void resolve_uncontrolled_offsets(Scene& scene) {
  std::ifstream in(scene.file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in) throw InputError(scene.file.string() + ": cannot read scene file");
  const std::vector<int> marked = offsets_from_uncontrolled(nlohmann::json::parse(text.str()), scene);
  if (marked.empty()) return;
  auto sys = make_system(scene);
  VecX x0, v0;
  sys->initial_state(x0, v0);
  Rollout r;
  if (!simulate_frames(*sys, x0, v0, scene.time, r)) {
    const std::string why = sys->divergence_reason();
    throw InputError(scene.file.string() + ": a keyframe's offset \"from\": \"uncontrolled\" needs the motion "
                     "without controls, and that simulation diverged at step " + std::to_string(r.diverged_at) +
                     (why.empty() ? "" : ": " + why));
  }
  const Trajectory frames = frames_of(r, scene.time, sys->particles());
  for (int k : marked) add_uncontrolled(scene.objectives[size_t(k)], frames);
}

void write_resolved_targets(nlohmann::json& scene_json, const Scene& scene) {
  const std::vector<int> marked = offsets_from_uncontrolled(scene_json, scene);
  if (marked.empty()) return;
  size_t n = 0;  // the file's index of each marked objective, in the same order
  for (nlohmann::json& o : scene_json.at("objectives")) {
    if (!asks(o)) continue;
    o.erase("offset");
    o.erase("from");
    std::visit(Overloaded{[&](const PositionKeyframe& k) {
                            o["targets"] = nlohmann::json::array();
                            for (const Vec3& p : k.targets) o["targets"].push_back(json_point(p));
                          },
                          [&](const CenterOfMassKeyframe& k) { o["target"] = json_point(k.target); },
                          [](const auto&) { no_offset(); }},
               scene.objectives[size_t(marked[n++])].kind);
  }
}

}  // namespace kf
