#include "scene/scene_schema.h"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>

#include "core/trajectory.h"
#include "scene/scene.h"

namespace kf {

namespace fs = std::filesystem;

namespace {

// A flock with every flock objective type and shape kind (an SVG path inline and from a file), a schedule,
// a first step and a camera.
std::string flock_scene(int frames, int agents) {
  return R"({
  "$schema": "scene.schema.json",
  "seed": 3,
  "time": {"fps": 30, "substeps": 1, "frames": )" +
         std::to_string(frames) + R"(},
  "flock": {"agents": )" +
         std::to_string(agents) + R"(},
  "objectives": [
    {"type": "position", "frame": 5, "particles": [0], "targets": [[0, 0, 0]]},
    {"type": "velocity", "frame": 5, "targets": [[0, 0, 0]]},
    {"type": "center_of_mass", "frame": 5, "target": [0, 0, 0]},
    {"type": "shape", "frame": 10, "polygon": [[0, 0], [1, 0], [0, 1]], "coverage": {"weight": 1}},
    {"type": "shape", "frame": 10, "circle": {"center": [0, 0], "radius": 2, "segments": 16}},
    {"type": "shape", "frame": 10, "ring": {"center": [0, 0], "inner_radius": 1, "outer_radius": 4, "segments": 16},
     "holes": [{"polygon": [[2, -0.2], [2.5, -0.2], [2.5, 0.2]]}, {"circle": {"center": [-2.5, 0], "radius": 0.3}}]},
    {"type": "shape", "frame": 10, "svg_path": {"d": "M 0 0 H 8 V 8 H 0 Z M 2 2 h 2 v 2 h -2 z", "scale": 0.5,
                                                 "offset": [-2, -2], "tolerance": 0.02}},
    {"type": "shape", "frame": 10, "svg_path": {"file": "shape.svg"}}
  ],
  "controls": {"kind": "per_frame"},
  "optimizer": {"schedule": [{"substeps": 1, "controls": {"kind": "per_frame_lattice", "from_frame": 1}}, {"substeps": 1}],
                "first_step": 0.5},
  "render": {"camera": {"eye": [0, 5, 5], "target": [0, 0, 0]}}
})";
}

// A cape with every collider shape, arch and height keyframes and a schedule whose first stage has its own
// controls.
// `pins` and `anchors` are the alternatives the second cape takes the other way.
std::string cape_scene(int frames, int n, const std::string& anchors, const std::string& extra) {
  const bool nodes = anchors.find("nodes") != std::string::npos;
  return R"({
  "time": {"frames": )" +
         std::to_string(frames) + R"(},
  "cloth": {"nx": )" + std::to_string(n) +
         R"(, "ny": )" + std::to_string(n) + R"(, "pins": )" + (nodes ? R"("top_edge")" : "[0, 1]") + R"(,
    "colliders": [{"type": "ground"}, {"type": "sphere"}, {"type": "torus"}, {"type": "capsule"},
                  {"type": "box"}, {"type": "rectangle"}]},
  "character": {"file": "character.x", "anchors": )" +
         anchors + extra + R"(},
  "objectives": [{"type": "arch", "frame": 10, "axis_point": [0, 0, 0], "radius": 1},
                 {"type": "height", "frame": 10, "particles": "bottom_edge", "height": 0.5},
                 {"type": "position", "frame": 5, "particles": {"row": 0, "column": 0, "i": [0, 1], "j": [0, 1],
                  "u": [0, 5], "v": [0, 5]}, "offset": [0, 0.1, 0], "from": "rest"},
                 {"type": "center_of_mass", "frame": 5, "particles": "top_edge", "offset": [0, 0.1, 0]}],
  "controls": {"kind": "initial_velocity"},
  "optimizer": {"schedule": [{"substeps": 1, "controls": {"kind": "initial_rigid_velocity"}}, {"substeps": 2}],
                "throw_search": 64}
})";
}

// A cloth from a mesh file with every mesh key, pins and a keyframe's particles by region, or (`named`) by
// the file's named vertex set.
std::string mesh_cloth_scene(int frames, bool named) {
  const std::string pins = named ? R"({"group": "all"})" : R"({"min": [-1, -1, -1], "max": [0.5, 1, 0.5]})";
  const std::string particles = named ? R"({"group": "all"})" : R"({"min": [0.5, -1, -1], "max": [2, 1, 2]})";
  return R"({
  "time": {"frames": )" + std::to_string(frames) + R"(},
  "cloth": {"mesh": {"file": "cloth.obj", "scale": 1, "up_axis": "y", "rotation": {"axis": [0, 1, 0], "degrees": 0},
                     "offset": [0, 0, 0]},
            "mass_by": "area", "pins": )" + pins + R"(,
            "self": {"enabled": true, "thickness": 0.02, "stiffness": 500, "friction": 0, "friction_velocity": 0.01}},
  "objectives": [{"type": "center_of_mass", "frame": 5, "particles": )" + particles + R"(, "target": [0, 0, 0]}],
  "controls": {"kind": "per_frame"}
})";
}

}  // namespace

std::vector<ParamLog> every_branch_logs(const fs::path& scratch) {
  fs::create_directories(scratch);
  // Parsing only checks that the character's file exists; its meshes and nodes are read when simulating.
  std::ofstream(scratch / "character.x") << "xof 0303txt 0032\n";
  std::ofstream(scratch / "cloth.obj") << "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\ng all\nf 1 2 3 4\n";
  std::ofstream(scratch / "shape.svg") << "<svg><path d=\"M 0 0 A 1 1 0 0 1 2 0 Z\"/></svg>\n";
  struct Size {
    int frames, agents, cloth_n;
  };
  std::vector<ParamLog> logs;
  for (const Size z : {Size{10, 4, 3}, Size{12, 5, 4}}) {
    // A run of the cape's particle count for the character's start and end target to read.
    const std::string run = "run_" + std::to_string(z.cloth_n);
    Trajectory t;
    t.particles = z.cloth_n * z.cloth_n;
    for (int f = 0; f < 2; ++f) t.x.push_back(VecX::Zero(3 * t.particles)), t.v.push_back(VecX::Zero(3 * t.particles));
    fs::create_directories(scratch / run);
    save_trajectory(scratch / run / "trajectory.bin", t);
    const std::vector<std::string> texts = {
        flock_scene(z.frames, z.agents),
        cape_scene(z.frames, z.cloth_n, R"({"nodes": ["B_Clavicle_Left", "B_Clavicle_Right"]})",
                   R"(, "time": [[0, 0], [10, 0.3]], "root": {"keys": [{"frame": 0}]},
                      "start": {"run": ")" + run + R"(", "frame": 0}, "end_target": {"run": ")" + run +
                       R"(", "frame": 1})"),
        cape_scene(z.frames, z.cloth_n, R"({"mesh": "Torso", "points": [[0, 0, 0], [1, 0, 0]]})", ""),
        cape_scene(z.frames, z.cloth_n, R"("none")", R"(, "scale": 0.01, "up_axis": "z", "loop": true)"),
        mesh_cloth_scene(z.frames, false),
        mesh_cloth_scene(z.frames, true),
    };
    for (const std::string& text : texts) {
      ParamLog log;
      parse_scene(text, scratch / "scene.json", &log);
      logs.push_back(std::move(log));
    }
  }
  return logs;
}

namespace {

// A key (or the root) with every read of it, merged over the logs. Array elements are the child "*".
struct KeyNode {
  std::vector<ParamRead> reads;
  std::set<std::string> instances;    // "log#pointer" of each object this node was, where keys were read below it
  std::set<std::string> required_in;  // "log#pointer" of each parent object that read this key as required
  std::map<std::string, KeyNode> keys;
};

void insert(KeyNode& root, const ParamRead& r, size_t log) {
  const std::string tag = std::to_string(log) + "#";
  KeyNode* node = &root;
  std::string concrete;
  node->instances.insert(tag);
  std::stringstream ss(r.pointer.substr(1));
  std::vector<std::string> parts;
  for (std::string part; std::getline(ss, part, '/');) parts.push_back(part);
  for (size_t i = 0; i < parts.size(); ++i) {
    const std::string& part = parts[i];
    const bool index = !part.empty() && std::all_of(part.begin(), part.end(), ::isdigit);
    const std::string parent = concrete;
    concrete += "/" + part;
    // Pointers escape '~' and '/' (RFC 6901); schema property names are the keys themselves.
    std::string key = part;
    for (size_t p; (p = key.find("~1")) != std::string::npos;) key.replace(p, 2, "/");
    for (size_t p; (p = key.find("~0")) != std::string::npos;) key.replace(p, 2, "~");
    node = &node->keys[index ? "*" : key];
    if (i + 1 < parts.size()) {
      node->instances.insert(tag + concrete);
      continue;
    }
    node->reads.push_back(r);
    if (r.required) node->required_in.insert(tag + parent);
  }
}

Json object_schema(const KeyNode& n);

// A bound every read agrees on, as the JSON number of the key's type; null when reads disagree (it follows
// the scene, such as a keyframe's frame within the scene's frames).
Json agreed(const std::vector<const ParamRead*>& reads, double ParamRead::*bound, bool integer) {
  const double v = reads.front()->*bound;
  for (const ParamRead* r : reads)
    if (r->*bound != v) return nullptr;
  return integer ? Json(static_cast<long long>(v)) : Json(v);
}

// {"type": "number", "minimum", "maximum"} from the reads' range, for a value or each number of a list.
Json scalar_schema(const char* type, const std::vector<const ParamRead*>& reads) {
  Json s = {{"type", type}};
  const bool integer = std::string(type) == "integer";
  if (Json lo = agreed(reads, &ParamRead::lo, integer); !lo.is_null()) s["minimum"] = lo;
  if (Json hi = agreed(reads, &ParamRead::hi, integer); !hi.is_null()) s["maximum"] = hi;
  return s;
}

Json list_of(Json items, int min_count, int max_count = 0) {
  Json s = {{"type", "array"}, {"items", std::move(items)}};
  if (min_count > 0) s["minItems"] = min_count;
  if (max_count > 0) s["maxItems"] = max_count;
  return s;
}

// The schema of one type a key was read as.
Json typed_schema(const std::string& type, const std::vector<const ParamRead*>& reads, const KeyNode& n) {
  int min_count = reads.front()->min_count;
  for (const ParamRead* r : reads) min_count = std::min(min_count, r->min_count);
  Json s;
  if (type == "object") s = object_schema(n);
  else if (type == "array") s = list_of(object_schema(n.keys.at("*")), min_count);
  else if (type == "number" || type == "integer") s = scalar_schema(type.c_str(), reads);
  else if (type == "boolean") s = {{"type", "boolean"}};
  else if (type == "string" || type == "strings") {
    Json str = {{"type", "string"}};
    std::vector<std::string> choices;
    for (const ParamRead* r : reads)
      for (const std::string& c : r->choices)
        if (std::find(choices.begin(), choices.end(), c) == choices.end()) choices.push_back(c);
    if (!choices.empty()) str["enum"] = choices;
    s = type == "string" ? str : list_of(str, min_count);
  } else if (type == "vec3") s = list_of(scalar_schema("number", reads), 3, 3);
  else if (type == "numbers") s = list_of(scalar_schema("number", reads), min_count);
  else if (type == "integers") s = list_of(scalar_schema("integer", reads), min_count);
  else if (type == "points2") s = list_of(list_of(scalar_schema("number", reads), 2, 2), min_count);
  else if (type == "points3") s = list_of(list_of(scalar_schema("number", reads), 3, 3), min_count);
  else throw std::logic_error("scene schema: no schema for the read type \"" + type + "\"");
  const Json& def = reads.front()->default_value;
  const bool same_default =
      std::all_of(reads.begin(), reads.end(), [&](const ParamRead* r) { return r->default_value == def; });
  if (!def.is_null() && same_default) s["default"] = def;
  return s;
}

// A key read as one type, or as several (cloth "pins": a named set or indices) as anyOf.
Json key_schema(const KeyNode& n) {
  std::vector<std::string> types;
  std::map<std::string, std::vector<const ParamRead*>> by_type;
  for (const ParamRead& r : n.reads) {
    if (!by_type.count(r.type)) types.push_back(r.type);
    by_type[r.type].push_back(&r);
  }
  if (types.size() == 1) return typed_schema(types.front(), by_type[types.front()], n);
  Json any = Json::array();
  for (const std::string& t : types) any.push_back(typed_schema(t, by_type[t], n));
  return {{"anyOf", any}};
}

Json object_schema(const KeyNode& n) {
  Json s = {{"type", "object"}, {"additionalProperties", false}};
  Json properties = Json::object(), required = Json::array();
  for (const auto& [key, child] : n.keys) {
    if (key == "*" || child.reads.empty()) continue;
    properties[key] = key_schema(child);
    const bool always_required = std::all_of(child.reads.begin(), child.reads.end(),
                                             [](const ParamRead& r) { return r.required; });
    if (always_required && child.required_in == n.instances) required.push_back(key);
  }
  s["properties"] = properties;
  if (!required.empty()) s["required"] = required;
  return s;
}

}  // namespace

Json scene_schema(const std::vector<ParamLog>& logs) {
  KeyNode root;
  for (size_t i = 0; i < logs.size(); ++i)
    for (const ParamRead& r : logs[i].reads) insert(root, r, i);
  Json s = object_schema(root);
  // Exactly one system: with both, both branches match and oneOf fails; with neither, none does.
  Json one_system = Json::array();
  for (const char* system : {"flock", "cloth"}) one_system.push_back(Json{{"required", Json::array({system})}});
  s["oneOf"] = one_system;
  s["$schema"] = "http://json-schema.org/draft-07/schema#";
  s["title"] = "keyframe scene";
  s["description"] =
      "Generated by `keyframe schema` from the keys keyframe's scene parser reads; scenes/README.md says what "
      "each key means. The parser also checks what this schema leaves out: bounds that follow the scene (a "
      "keyframe's frame within the scene's frames, particle indices) and most rules between keys (this schema's "
      "oneOf states the rule of exactly one of \"flock\" or \"cloth\").";
  return s;
}

}  // namespace kf
