#include "scene/character_spec.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>

#include "core/error.h"
#include "core/json_depth.h"
#include "core/trajectory.h"
#include "scene/params.h"
#include "scene/scene.h"

namespace kf {

double animation_time(const CharacterSpec& spec, double frame) {
  const auto& k = spec.time_keys;
  if (frame <= k.front().x()) return k.front().y();
  for (size_t i = 1; i < k.size(); ++i)
    if (frame <= k[i].x()) {
      const double s = (frame - k[i - 1].x()) / (k[i].x() - k[i - 1].x());
      return k[i - 1].y() + s * (k[i].y() - k[i - 1].y());
    }
  return k.back().y();
}

Eigen::Affine3d character_conform(const CharacterSpec& spec) {
  Mat3 up = Mat3::Identity();
  if (spec.z_up) up << 1, 0, 0, 0, 0, 1, 0, -1, 0;  // (x, y, z) -> (x, z, -y)
  Eigen::Affine3d conform = Eigen::Affine3d::Identity();
  conform.linear() = spec.scale * up;
  return conform;
}

Eigen::Affine3d character_placement(const CharacterSpec& spec, double frame) {
  const Eigen::Affine3d placement = Eigen::Translation3d(spec.offset) * character_conform(spec);
  const auto& k = spec.root.keys;
  if (k.empty()) return placement;
  Vec3 translate = k.front().translate;
  double angle = k.front().angle;
  if (frame >= k.back().frame) {
    translate = k.back().translate, angle = k.back().angle;
  } else {
    for (size_t i = 1; i < k.size(); ++i)
      if (frame > k[i - 1].frame && frame <= k[i].frame) {
        const double s = (frame - k[i - 1].frame) / (k[i].frame - k[i - 1].frame);
        translate = k[i - 1].translate + s * (k[i].translate - k[i - 1].translate);
        angle = k[i - 1].angle + s * (k[i].angle - k[i - 1].angle);
        break;
      }
  }
  const Vec3& p = spec.root.pivot;
  return Eigen::Translation3d(spec.offset) * Eigen::Translation3d(translate + p) *
         Eigen::AngleAxisd(angle * M_PI / 180.0, spec.root.axis) * Eigen::Translation3d(-p) * character_conform(spec);
}

namespace {

RootMotion parse_root_motion(Block& b) {
  RootMotion r;
  r.pivot = b.vec3("pivot", r.pivot);
  r.axis = b.vec3("axis", r.axis);
  if (!(r.axis.norm() > 1e-9)) b.fail("axis", "expected a non-zero axis");
  r.axis.normalize();
  for (Block& key : b.array("keys", 1)) {
    RootMotion::Key k;
    k.frame = key.number("frame", -1e6, 1e6);
    k.translate = key.vec3("translate", Vec3::Zero());
    k.angle = key.number("angle", 0.0, -1e5, 1e5);
    if (!r.keys.empty() && !(k.frame > r.keys.back().frame)) key.fail("frame", "expected frames in ascending order");
    key.finish();
    r.keys.push_back(k);
  }
  b.finish();
  return r;
}

CapeAnchors parse_cape_anchors(Block& b) {
  CapeAnchors a;
  a.where = b.file() + ": " + b.json_pointer();
  a.mesh = b.string("mesh", "");
  if (b.has("points") == b.has("nodes"))
    b.fail_here("expected exactly one of \"points\" ([[x, y, z], ...] in the mesh file's frame) or \"nodes\" "
                "([\"name\", ...]; keyframe inspect MESH lists them)");
  if (b.has("points")) a.points = b.points3("points", 2, -100.0, 100.0);
  else a.nodes = b.strings("nodes", 2);
  b.finish();
  return a;
}

// One frame of a run's trajectory, checked against the cape's particle count.
void load_run_state(Block& b, const std::filesystem::path& run, int frame, int particles, VecX& x, VecX& v) {
  const Trajectory t = load_trajectory(run / "trajectory.bin");
  if (t.particles != particles)
    b.fail("run", "expected a run of " + std::to_string(particles) + " particles, got " + std::to_string(t.particles));
  if (frame >= t.frames())
    b.fail("frame", "expected a frame below " + std::to_string(t.frames()) + " (the run's length)");
  x = t.x[frame];
  v = t.v[frame];
}

}  // namespace

std::filesystem::path cape_anchors_file(const std::filesystem::path& mesh_file) {
  std::filesystem::path p = mesh_file;
  return p.replace_extension(".cape.json");
}

CapeAnchors load_cape_anchors(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot open the cape anchors file");
  Json j;
  try {
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    check_json_depth(text, file.string());
    j = Json::parse(text);
  } catch (const Json::exception& e) {
    throw InputError(file.string() + ": not valid JSON (" + e.what() + ")");
  }
  Block b(j, file.string());
  return parse_cape_anchors(b);
}

namespace {

// The cape's anchors: the "anchors" block (its points in metres, Y up, taken to the file's frame), "none",
// or the file beside the mesh (the asset's own, in the file's frame), or none without one.
CapeAnchors read_cape_anchors(Block& b, const CharacterSpec& c) {
  if (b.has("anchors") && b.json().at("anchors").is_string()) {
    b.string("anchors", "none", {"none"});
    CapeAnchors none;
    none.none = true;
    return none;
  }
  if (auto anchors = b.optional_child("anchors")) {
    CapeAnchors a = parse_cape_anchors(*anchors);
    const Eigen::Affine3d to_file = character_conform(c).inverse();
    for (Vec3& p : a.points) p = to_file * p;
    return a;
  }
  const auto file = cape_anchors_file(c.file);
  if (std::error_code ec; !std::filesystem::exists(file, ec)) {
    CapeAnchors none;
    none.none = true;
    return none;
  }
  return load_cape_anchors(file);
}

void read_body_contact(Block body, CharacterSpec& c) {
  c.body_thickness = body.number("thickness", c.body_thickness, 1e-5, 1.0);
  c.body_stiffness = body.number("stiffness", c.body_stiffness, 0.0, 1e8);
  c.body_search = body.number("search", c.body_search, 0.0, 1.0);
  c.body_friction = body.number("friction", c.body_friction, 0.0, 10.0);
  c.body_friction_velocity = body.number("friction_velocity", c.body_friction_velocity, 1e-6, 100.0);
  body.finish();
}

void read_self_contact(Block self, CharacterSpec& c) {
  c.self_collision = self.boolean("enabled", c.self_collision);
  c.self_thickness = self.number("thickness", c.self_thickness, 1e-5, 1.0);
  c.self_stiffness = self.number("stiffness", c.self_stiffness, 0.0, 1e8);
  c.self_friction = self.number("friction", c.self_friction, 0.0, 10.0);
  c.self_friction_velocity = self.number("friction_velocity", c.self_friction_velocity, 1e-6, 100.0);
  self.finish();
}

// "end_target": the state of another run's frame, as position and velocity keyframes at the last frame.
void read_end_target(Block& end, CharacterSpec& c, Scene& scene, int p) {
  c.target_run = scene.directory / end.string("run");
  c.target_frame = end.integer("frame", 0, 0, 1'000'000);
  const double wx = end.number("position_weight", 1.0, 0.0, 1e12);
  const double wv = end.number("velocity_weight", 0.01, 0.0, 1e12);
  VecX x, v;
  load_run_state(end, c.target_run, c.target_frame, p, x, v);
  end.finish();
  PositionKeyframe position;
  VelocityKeyframe velocity;
  for (int i = 0; i < p; ++i) position.targets.push_back(seg(x, i)), velocity.targets.push_back(seg(v, i));
  const int last = scene.time.frames;
  scene.objectives.push_back({std::move(position), last, wx, {}, ObjectiveSource::kEndTarget});
  scene.objectives.push_back({std::move(velocity), last, wv, {}, ObjectiveSource::kEndTarget});
}

}  // namespace

CharacterSpec parse_character_spec(Block b, Scene& scene) {
  if (!scene.cloth) b.fail_here("expected a \"cloth\" block for the cape (a character needs a cloth)");
  if (scene.cloth->self_stated)
    throw InputError(b.file() + ": /cloth/self: expected no self block on a cape (its self contact is "
                     "\"character\": {\"self\": ...})");
  CharacterSpec c;
  c.where = b.file() + ": " + b.json_pointer();
  const int p = scene.particles();
  c.file = scene.directory / b.string("file");
  // A missing mesh is named here, before the anchors that would be looked for beside it.
  if (std::error_code ec; !std::filesystem::is_regular_file(c.file, ec))
    b.fail("file", "no such mesh file " + c.file.string());
  c.animation = b.integer("animation", 0, 0, 1000);
  if (b.has("time")) {
    c.time_keys = b.points2("time", 1, -1e6, 1e6);
    for (size_t i = 1; i < c.time_keys.size(); ++i)
      if (!(c.time_keys[i].x() > c.time_keys[i - 1].x()))
        b.fail_rel("/time/" + std::to_string(i), "expected frames in ascending order");
  } else {
    // The animation at its own rate from its start; the character holds its last pose after its end.
    c.time_keys = {{0.0, 0.0}, {double(scene.time.frames), scene.time.frames / scene.time.fps}};
  }
  c.scale = b.number("scale", 1.0, 1e-6, 1e6);
  c.z_up = b.string("up_axis", "y", {"y", "z"}) == "z";
  c.loop = b.boolean("loop", false);
  c.offset = b.vec3("offset", Vec3::Zero());
  if (auto root = b.optional_child("root")) c.root = parse_root_motion(*root);
  c.anchors = read_cape_anchors(b, c);
  read_body_contact(b.child("body"), c);
  read_self_contact(b.child("self"), c);
  if (auto start = b.optional_child("start")) {
    c.start_run = scene.directory / start->string("run");
    c.start_frame = start->integer("frame", 0, 0, 1'000'000);
    load_run_state(*start, c.start_run, c.start_frame, p, c.start_x, c.start_v);
    start->finish();
  }
  if (auto end = b.optional_child("end_target")) read_end_target(*end, c, scene, p);
  b.finish();
  return c;
}

}  // namespace kf
