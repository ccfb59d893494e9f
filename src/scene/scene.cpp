#include "scene/scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "core/ground_region.h"
#include "core/json_depth.h"
#include "scene/cloth_mesh_spec.h"
#include "scene/control_kind.h"
#include "scene/params.h"
#include "scene/particle_selector.h"
#include "scene/svg_shape_spec.h"

namespace kf {

int Scene::particles() const {
  if (flock) return flock->agents;
  if (cloth) return cloth->particles();
  return 0;
}

namespace {

TimeSpec parse_time(Block b) {
  TimeSpec t;
  t.fps = b.number("fps", t.fps, 1, 10000);
  t.substeps = b.integer("substeps", t.substeps, 1, 10000);
  t.frames = b.integer("frames", t.frames, 1, 1'000'000);
  b.finish();
  if (t.steps() > 10'000'000) b.fail_here("too many steps (frames x substeps must be at most 1e7)");
  return t;
}

// Each keyframe type reads its own keys; the table below names the types the scene file may use.
// The particles a keyframe names (all when it names none), in order.
std::vector<int> selected(const ObjectiveSpec& o, int particles) {
  if (!o.particles.empty()) return o.particles;
  std::vector<int> all(size_t(particles), 0);
  for (int i = 0; i < particles; ++i) all[size_t(i)] = i;
  return all;
}

// A flock's agents stay on the ground, so an offset from where they would be cannot leave it.
void check_offsets_along_ground(Block& b, const Scene& s, bool rigid, const std::vector<Vec3>& offsets) {
  if (!s.flock) return;
  for (size_t k = 0; k < offsets.size(); ++k)
    if (std::abs(offsets[k].y()) > 1e-9)
      b.fail_rel(rigid ? "/offset" : "/offset/" + std::to_string(k),
                 "expected an offset along the ground, dy = 0 (a flock moves on the ground and cannot move by dy = " +
                     Json(offsets[k].y()).dump() + ")");
}

// "offset" (one for the whole set, or one per particle) from each particle's place on the rest sheet
// ("from": "rest", the cloth block's layout), instead of absolute "targets"; or from where it is at the
// keyframe without controls ("from": "uncontrolled": the offsets stay the targets until a job resolves them,
// app/uncontrolled_targets.h).
std::vector<Vec3> offsets_from_rest(Block& b, const std::vector<int>& set, const Scene& s) {
  if (b.has("targets")) b.fail("offset", "expected either \"targets\" or \"offset\", not both");
  const bool uncontrolled = b.string("from", "rest", {"rest", "uncontrolled"}) == "uncontrolled";
  if (!s.cloth && !uncontrolled)
    b.fail("offset", "expected absolute \"targets\": an offset from the rest position needs a cloth (a flock's "
                     "agents start at seeded random places)");
  // [dx, dy, dz]: the whole set moved rigidly; [[dx, dy, dz], ...]: one per particle.
  const Json& given = b.json().at("offset");
  const bool rigid = given.is_array() && !given.empty() && given.front().is_number();
  const std::vector<Vec3> offsets = rigid ? std::vector<Vec3>{b.vec3("offset")} : b.points3("offset", 1);
  if (offsets.size() != 1 && offsets.size() != set.size())
    b.fail("offset", "expected [dx, dy, dz] (the whole set moved rigidly) or one offset per particle (" +
                         std::to_string(set.size()) + "), got " + std::to_string(offsets.size()));
  if (uncontrolled) {
    check_offsets_along_ground(b, s, rigid, offsets);
    return offsets;
  }
  std::vector<Vec3> targets;
  for (size_t k = 0; k < set.size(); ++k)
    targets.push_back(rest_position(*s.cloth, set[k]) + offsets[offsets.size() == 1 ? 0 : k]);
  return targets;
}

// Flocks live on the ground (their controls have no vertical component): a position off it can never be met.
void check_on_ground(Block& b, const Scene& s, const std::string& key, const std::vector<Vec3>& points) {
  if (!s.flock) return;
  for (size_t k = 0; k < points.size(); ++k)
    if (std::abs(points[k].y()) > 1e-9)
      b.fail_rel("/" + key + (key == "target" ? "" : "/" + std::to_string(k)),
                 "expected a point on the ground, y = 0 (a flock moves on the ground and cannot reach y = " +
                     Json(points[k].y()).dump() + ")");
}

std::vector<Vec3> parse_targets(Block& b, const ObjectiveSpec& o, const Scene& s, bool positions) {
  const int particles = s.particles();
  if (positions && b.has("offset")) return offsets_from_rest(b, selected(o, particles), s);
  std::vector<Vec3> targets = b.points3("targets", 1);
  const size_t n = o.particles.empty() ? size_t(particles) : o.particles.size();
  if (targets.size() != 1 && targets.size() != n)
    b.fail("targets", "expected 1 target or one per particle (" + std::to_string(n) + "), got " +
                          std::to_string(targets.size()));
  if (positions) check_on_ground(b, s, "targets", targets);
  return targets;
}

ObjectiveKind parse_position(Block& b, const ObjectiveSpec& o, const Scene& s) {
  return PositionKeyframe{parse_targets(b, o, s, true)};
}

ObjectiveKind parse_velocity(Block& b, const ObjectiveSpec& o, const Scene& s) {
  return VelocityKeyframe{parse_targets(b, o, s, false)};
}

// "target", or "offset" from the rest sheet's centre of mass of the particles ("from": "rest").
ObjectiveKind parse_center_of_mass(Block& b, const ObjectiveSpec& o, const Scene& s) {
  if (!b.has("offset")) {
    const Vec3 target = b.vec3("target");
    check_on_ground(b, s, "target", {target});
    return CenterOfMassKeyframe{target};
  }
  if (b.has("target")) b.fail("offset", "expected either \"target\" or \"offset\", not both");
  if (b.string("from", "rest", {"rest", "uncontrolled"}) == "uncontrolled") {
    const Vec3 offset = b.vec3("offset");  // resolved by a job's uncontrolled simulation
    check_offsets_along_ground(b, s, true, {offset});
    return CenterOfMassKeyframe{offset};
  }
  if (!s.cloth)
    b.fail("offset", "expected an absolute \"target\": an offset from the rest position needs a cloth");
  const std::vector<int> set = selected(o, s.particles());
  Vec3 mean = Vec3::Zero();
  for (int i : set) mean += rest_position(*s.cloth, i) / double(set.size());
  return CenterOfMassKeyframe{mean + b.vec3("offset")};
}

// The regular polygon through `n` points on a circle on the ground, counter-clockwise in (x, z) (clockwise
// seen from above, where z runs toward the viewer).
std::vector<Vec2> circle_loop(const Vec2& center, double r, int n) {
  std::vector<Vec2> poly;
  for (int i = 0; i < n; ++i)
    poly.push_back(center + r * Vec2(std::cos(2 * M_PI * i / n), std::sin(2 * M_PI * i / n)));
  return poly;
}

Vec2 read_center(Block& c) {
  const std::vector<double> center = c.numbers("center", 2, -1e6, 1e6);
  if (center.size() != 2) c.fail("center", "expected [x, z]");
  return {center[0], center[1]};
}

std::vector<Vec2> parse_circle(Block c) {
  const Vec2 center = read_center(c);
  const double r = c.number("radius", 1e-3, 1e4);
  const int n = c.integer("segments", 64, 3, 4096);
  c.finish();
  return circle_loop(center, r, n);
}

// An annulus: the outer circle, and the inner one as its hole.
std::pair<std::vector<Vec2>, std::vector<Vec2>> parse_ring(Block c) {
  const Vec2 center = read_center(c);
  const double inner = c.number("inner_radius", 1e-3, 1e4);
  const double outer = c.number("outer_radius", 1e-3, 1e4);
  if (!(outer > inner)) c.fail("outer_radius", "expected more than \"inner_radius\"");
  const int n = c.integer("segments", 64, 3, 4096);
  c.finish();
  return {circle_loop(center, outer, n), circle_loop(center, inner, n)};
}

// A loop given as "polygon" [[x, z], ...] or "circle" {...}: one of a shape's holes, or its outline.
std::vector<Vec2> parse_loop(Block& b) {
  if (b.has("polygon") + b.has("circle") != 1)
    b.fail_here("expected one of \"polygon\" [[x, z], ...] or \"circle\" {\"center\": [x, z], \"radius\"}");
  return b.has("circle") ? parse_circle(b.child("circle")) : b.points2("polygon", 3);
}

ObjectiveKind parse_shape(Block& b, const ObjectiveSpec&, const Scene& s) {
  if (!s.flock) b.fail("type", "\"shape\" keyframes are for flocks; use \"position\" or \"arch\" for cloth");
  ShapeKeyframe k;
  if (b.has("polygon") + b.has("circle") + b.has("ring") + b.has("svg_path") != 1)
    b.fail_here("expected one of \"polygon\" [[x, z], ...], \"circle\" {\"center\": [x, z], \"radius\"}, "
                "\"ring\" {\"center\", \"inner_radius\", \"outer_radius\"} or \"svg_path\" {\"d\" or \"file\"}");
  if (b.has("ring")) {
    auto [outer, inner] = parse_ring(b.child("ring"));
    k.polygon = std::move(outer);
    k.holes.push_back(std::move(inner));
  } else if (b.has("svg_path")) {
    ShapeLoops loops = parse_svg_shape(b.child("svg_path"), s.directory);
    k.polygon = std::move(loops.outer);
    k.holes = std::move(loops.holes);
  } else {
    k.polygon = parse_loop(b);
  }
  for (Block& hole : b.array("holes")) {
    k.holes.push_back(parse_loop(hole));
    hole.finish();
  }
  if (const std::string problem = region_problem(GroundRegion(k.polygon, k.holes)); !problem.empty())
    b.fail("holes", problem);
  // Agents settle where the pull ends: a margin inside the edge keeps them counted inside.
  k.margin = b.number("margin", 0.1 * s.flock->avoidance.radius, 0.0, 1e4);
  Block c = b.child("coverage");
  k.coverage_weight = c.number("weight", 0.0, 0.0, 1e12);
  k.coverage_radius = c.number("radius", s.flock->avoidance.radius, 1e-3, 1e4);
  k.coverage_spacing = c.number("spacing", 0.5 * k.coverage_radius, 1e-3, 1e4);
  if (const double n = region_sample_count(k.polygon, k.coverage_spacing); k.coverage_weight > 0 && !(n <= 1e5)) {
    char msg[200];
    std::snprintf(msg, sizeof msg, "the coverage grid over the shape's bounding box would have %.3g samples (at most "
                  "100,000): raise \"spacing\"", n);
    c.fail("spacing", msg);
  }
  c.finish();
  return k;
}

ObjectiveKind parse_arch(Block& b, const ObjectiveSpec&, const Scene& s) {
  if (s.flock) b.fail("type", "\"arch\" keyframes are for cloth");
  ArchKeyframe k;
  k.axis_point = b.vec3("axis_point");
  k.axis = b.vec3("axis", Vec3::UnitZ(), -1e3, 1e3);
  if (k.axis.norm() < 1e-9) b.fail("axis", "expected a non-zero direction");
  k.axis.normalize();
  k.radius = b.number("radius", 1e-4, 1e4);
  return k;
}

ObjectiveKind parse_height(Block& b, const ObjectiveSpec&, const Scene& s) {
  if (s.flock) b.fail("type", "\"height\" keyframes are for cloth");
  return HeightKeyframe{b.number("height", -1e4, 1e4)};
}

struct ObjectiveType {
  const char* name;
  ObjectiveKind (*parse)(Block&, const ObjectiveSpec&, const Scene&);
};
const ObjectiveType kObjectiveTypes[] = {
    {PositionKeyframe::kName, parse_position},         {VelocityKeyframe::kName, parse_velocity},
    {CenterOfMassKeyframe::kName, parse_center_of_mass}, {ShapeKeyframe::kName, parse_shape},
    {ArchKeyframe::kName, parse_arch},         {HeightKeyframe::kName, parse_height},
};

ObjectiveSpec parse_objective(Block b, const Scene& s) {
  std::vector<std::string> names;
  for (const ObjectiveType& t : kObjectiveTypes) names.push_back(t.name);
  ObjectiveSpec o;
  const std::string type = b.string("type", names);
  o.frame = b.integer("frame", 0, s.time.frames);
  o.weight = b.number("weight", 1.0, 0.0, 1e12);
  const int p = s.particles();
  if (b.has("particles") && s.cloth && is_rest_box(b.json().at("particles"))) {
    Block region = b.child("particles");
    o.particles = particles_in_region(region, *s.cloth);
  } else if (b.has("particles") && s.cloth && is_group_set(b.json().at("particles"))) {
    Block group = b.child("particles");
    o.particles = particles_in_group(group, *s.cloth);
  } else if (b.has("particles")) {
    o.particles = parse_particle_selector(b, "particles", p, s.cloth ? &*s.cloth : nullptr);
  }
  for (const ObjectiveType& t : kObjectiveTypes)
    if (type == t.name) o.kind = t.parse(b, o, s);
  b.finish();
  return o;
}

// What a controls block may hold: the scene's own (every kind but lattice forces), a stage's before an
// initial-velocity scene's last stage (the initial-velocity kinds), or a stage's before a per_frame scene's
// last stage (per_frame or per_frame_lattice, from a frame). frames: the scene's.
enum class ControlsBlock { kScene, kInitialStage, kForceStage };

ControlSpec parse_controls(Block b, ControlsBlock where, int frames, const ControlSpec& defaults = {}) {
  ControlSpec c = defaults;
  std::vector<ControlKind> kinds;
  if (where == ControlsBlock::kForceStage) {
    kinds = {ControlKind::kPerFrame, ControlKind::kPerFrameLattice};
  } else {
    kinds = {ControlKind::kInitialVelocity, ControlKind::kInitialRigidVelocity, ControlKind::kInitialLatticeVelocity};
    if (where == ControlsBlock::kScene) kinds.insert(kinds.begin(), {ControlKind::kPerStep, ControlKind::kPerFrame});
    else c.kind = ControlKind::kInitialRigidVelocity;
  }
  std::vector<std::string> names;
  for (ControlKind k : kinds) names.push_back(control_kind_name(k));
  const std::string kind = b.string("kind", control_kind_name(c.kind), names);
  for (ControlKind k : kinds)
    if (kind == control_kind_name(k)) c.kind = k;
  // Initial velocities are one control per particle, summed in the effort: at forces' weight the effort of a
  // throw outweighs centimetres of keyframe error on a small sheet, so they get a smaller default.
  const bool initial = control_timing(c.kind) == ControlTiming::kInitial;
  c.alpha = b.number("alpha", where == ControlsBlock::kForceStage ? c.alpha : initial ? kInitialVelocityAlpha : ControlSpec{}.alpha,
                     0.0, 1e6);
  if (where != ControlsBlock::kInitialStage) c.from_frame = b.integer("from_frame", c.from_frame, 0, std::max(0, frames - 1));
  b.finish();
  return c;
}

OptimizerSpec parse_optimizer(Block b, const ControlSpec& scene_controls, int frames) {
  OptimizerSpec o;
  o.max_evaluations = b.integer("max_evaluations", o.max_evaluations, 0, 1000000);
  o.ftol_rel = b.number("ftol_rel", o.ftol_rel, 0.0, 1.0);
  o.max_seconds = b.number("max_seconds", o.max_seconds, 0.0, 1e7);
  o.memory = b.integer("memory", o.memory, 1, 100);
  std::vector<Block> stages = b.array("schedule");
  for (size_t k = 0; k < stages.size(); ++k) {
    Block& stage = stages[k];
    StageSpec st;
    st.substeps = stage.integer("substeps", 1, 10000);
    st.max_evaluations = stage.integer("max_evaluations", st.max_evaluations, 0, 1000000);
    if (stage.has("controls")) {
      // Only between the initial-velocity kinds (their controls carry over as the velocities they give) or
      // between per-frame forces and lattice forces (carried over as the forces they give); the last stage
      // is the scene's own kind (what the run's controls.bin holds).
      if (scene_controls.kind != ControlKind::kInitialVelocity && scene_controls.kind != ControlKind::kPerFrame)
        stage.fail("controls", "a stage's own controls only with the scene's controls.kind \"initial_velocity\" or \"per_frame\"");
      if (k + 1 == stages.size()) stage.fail("controls", "the last stage uses the scene's controls (no \"controls\")");
      st.controls = scene_controls.kind == ControlKind::kPerFrame
                        ? parse_controls(stage.child("controls"), ControlsBlock::kForceStage, frames, scene_controls)
                        : parse_controls(stage.child("controls"), ControlsBlock::kInitialStage, frames);
    }
    stage.finish();
    o.schedule.push_back(st);
  }
  o.checkpoint_every = b.integer("checkpoint_every", o.checkpoint_every, 0, 10'000'000);
  o.max_memory = b.number("max_memory", o.max_memory, 0.0, 1e6);
  o.restarts = b.integer("restarts", o.restarts, 0, 1000);
  if (b.has("throw_search")) o.throw_search = b.integer("throw_search", 0, 0, 100000);
  o.split_schedule = b.string("split_schedule", o.split_schedule == SplitSchedule::kHeld ? "held" : "adaptive",
                               {"held", "adaptive"}) == "held"
                         ? SplitSchedule::kHeld
                         : SplitSchedule::kAdaptive;
  o.adjoint = adjoint_kind(b.string("adjoint", adjoint_name(o.adjoint), adjoint_names()));
  o.strategy = b.string("strategy", o.strategy == StagingStrategy::kAuto ? "auto" : "single", {"auto", "single"}) == "auto"
                   ? StagingStrategy::kAuto
                   : StagingStrategy::kSingle;
  o.window_frames = b.integer("window_frames", o.window_frames, 1, 1'000'000);
  o.window_growth = b.number("window_growth", o.window_growth, 1.0, 1e300);
  if (b.has("first_step")) o.first_step = b.number("first_step", 0.0, 0.0, 1e12);
  o.stop_when_reached = b.boolean("stop_when_reached", o.stop_when_reached);
  o.soft_keyframes = b.boolean("soft_keyframes", o.soft_keyframes);
  o.uniform_push = b.boolean("uniform_push", o.uniform_push);
  b.finish();
  return o;
}

}  // namespace

Scene parse_scene(const std::string& text, const std::filesystem::path& file, ParamLog* log) {
  check_json_depth(text, file.string());
  Json j;
  try {
    j = Json::parse(text);
  } catch (const Json::parse_error& e) {
    // nlohmann's message already carries the byte position.
    std::string what = e.what();
    auto pos = what.find("parse error");
    throw InputError(file.string() + ": not valid JSON: " + (pos == std::string::npos ? what : what.substr(pos)));
  } catch (const Json::exception& e) {
    std::string what = e.what();
    auto pos = what.find("] ");
    throw InputError(file.string() + ": not valid JSON: " + (pos == std::string::npos ? what : what.substr(pos + 2)));
  }
  Scene s;
  s.file = file;
  s.name = file.stem().string();
  s.directory = file.parent_path();
  Block root(j, file.string());
  if (log) {
    log->resolved = j;
    root.set_log(log);
  }
  // The schema an editor validates the file against (scenes/scene.schema.json, from `keyframe schema`).
  if (root.has("$schema")) root.string("$schema");
  s.seed = unsigned(root.integer("seed", 1, 0, 2'000'000'000));
  s.time = parse_time(root.child("time"));
  const bool has_flock = root.has("flock"), has_cloth = root.has("cloth");
  if (has_flock == has_cloth) root.fail_here("expected exactly one of \"flock\" or \"cloth\"");
  if (has_flock) {
    Block b = root.child("flock");
    s.flock = parse_flock_spec(b);
  } else {
    Block b = root.child("cloth");
    s.cloth = parse_cloth_spec(b, s.directory);
  }
  if (root.has("character")) s.character = parse_character_spec(root.child("character"), s);
  for (Block& b : root.array("objectives")) s.objectives.push_back(parse_objective(std::move(b), s));
  s.controls = parse_controls(root.child("controls"), ControlsBlock::kScene, s.time.frames);
  s.optimizer = parse_optimizer(root.child("optimizer"), s.controls, s.time.frames);
  {
    Block b = root.child("render");
    s.render = parse_render_spec(b);
  }
  root.finish();
  return s;
}

Scene shortened(Scene scene, int frames) {
  if (frames <= 0 || frames >= scene.time.frames) return scene;
  const double scale = double(frames) / scene.time.frames;
  for (auto& obj : scene.objectives) obj.frame = std::max(1, int(std::lround(obj.frame * scale)));
  scene.time.frames = frames;
  return scene;
}

Scene load_scene(const std::filesystem::path& file, ParamLog* log) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot open scene file");
  std::ostringstream os;
  os << in.rdbuf();
  if (!in && !in.eof()) throw InputError(file.string() + ": cannot read scene file");
  return parse_scene(os.str(), file, log);
}

}  // namespace kf
