// scenes/scene.schema.json is what `keyframe schema` generates, every shipped scene validates against it, and
// it rejects what the parser rejects for the mistakes a schema can see (a misspelt key, a wrong type, a
// number out of range, a missing required key, a value outside a list of choices).
//
// The validator below covers the part of JSON Schema draft-07 the generator writes, and refuses a schema
// using any keyword beyond it, so a schema it passes was checked in full.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "../reliability/cli_harness.h"
#include "scene/params.h"
#include "scene/scene.h"
#include "scene/scene_schema.h"

namespace kf {
namespace {

namespace fs = std::filesystem;

const fs::path kSource = KEYFRAME_SOURCE_DIR;

using reliability::read_text;

bool has_type(const Json& v, const std::string& type) {
  if (type == "object") return v.is_object();
  if (type == "array") return v.is_array();
  if (type == "string") return v.is_string();
  if (type == "boolean") return v.is_boolean();
  if (type == "number") return v.is_number();
  // draft-07: a number with no fractional part is an integer (the parser takes 3.0 as well).
  if (type == "integer") return v.is_number_integer() || (v.is_number_float() && v.get<double>() == std::floor(v.get<double>()));
  throw std::logic_error("validator: unknown type " + type);
}

// Problems of `v` (at JSON pointer `at`) against `schema`, one "pointer: what" each.
void validate(const Json& v, const Json& schema, const std::string& at, std::vector<std::string>& problems) {
  static const std::set<std::string> kKnown = {"type",     "properties", "additionalProperties", "required",
                                               "items",    "minItems",   "maxItems",             "minimum",
                                               "maximum",  "enum",       "anyOf",                "oneOf",    "default",
                                               "$schema",  "title",      "description"};
  for (auto it = schema.begin(); it != schema.end(); ++it)
    if (!kKnown.count(it.key())) throw std::logic_error("validator: keyword \"" + it.key() + "\" not supported");
  auto fail = [&](const std::string& what) { problems.push_back((at.empty() ? "/" : at) + ": " + what); };
  if (schema.contains("anyOf")) {
    for (const Json& alt : schema["anyOf"]) {
      std::vector<std::string> p;
      validate(v, alt, at, p);
      if (p.empty()) return;
    }
    return fail("matches none of anyOf");
  }
  if (schema.contains("oneOf")) {
    int matched = 0;
    for (const Json& alt : schema["oneOf"]) {
      std::vector<std::string> p;
      validate(v, alt, at, p);
      matched += p.empty();
    }
    if (matched != 1) fail("matches " + std::to_string(matched) + " of oneOf");
  }
  if (schema.contains("type") && !has_type(v, schema["type"])) return fail("expected " + schema["type"].get<std::string>());
  if (schema.contains("enum") && std::find(schema["enum"].begin(), schema["enum"].end(), v) == schema["enum"].end())
    return fail("not one of " + schema["enum"].dump());
  if (v.is_number()) {
    if (schema.contains("minimum") && v.get<double>() < schema["minimum"].get<double>()) fail("below minimum");
    if (schema.contains("maximum") && v.get<double>() > schema["maximum"].get<double>()) fail("above maximum");
  }
  if (v.is_array()) {
    if (schema.contains("minItems") && v.size() < schema["minItems"].get<size_t>()) fail("too few items");
    if (schema.contains("maxItems") && v.size() > schema["maxItems"].get<size_t>()) fail("too many items");
    if (schema.contains("items"))
      for (size_t i = 0; i < v.size(); ++i) validate(v[i], schema["items"], at + "/" + std::to_string(i), problems);
  }
  if (v.is_object()) {
    const Json props = schema.value("properties", Json::object());
    for (auto it = v.begin(); it != v.end(); ++it) {
      const std::string p = at + "/" + pointer_escape(it.key());
      if (props.contains(it.key())) validate(it.value(), props[it.key()], p, problems);
      else if (schema.value("additionalProperties", true) == false) problems.push_back(p + ": not allowed");
    }
    for (const Json& key : schema.value("required", Json::array()))
      if (!v.contains(key.get<std::string>())) fail("missing required \"" + key.get<std::string>() + "\"");
  }
}

std::vector<std::string> problems_of(const Json& v, const Json& schema) {
  std::vector<std::string> problems;
  validate(v, schema, "", problems);
  return problems;
}

std::vector<fs::path> shipped_scenes() {
  std::vector<fs::path> scenes;
  for (const auto& e : fs::recursive_directory_iterator(kSource / "scenes"))
    if (e.path().extension() == ".json" && e.path().filename() != "scene.schema.json") scenes.push_back(e.path());
  std::sort(scenes.begin(), scenes.end());
  return scenes;
}

class SceneSchema : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("keyframe_scene_schema_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    generated_ = scene_schema(every_branch_logs(dir_));
    committed_ = Json::parse(read_text(kSource / "scenes/scene.schema.json"));
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
  Json generated_, committed_;
};

TEST_F(SceneSchema, CommittedFileIsWhatKeyframeSchemaGenerates) {
  EXPECT_EQ(read_text(kSource / "scenes/scene.schema.json"), generated_.dump(2) + "\n")
      << "regenerate it: build/release/keyframe schema -o scenes/scene.schema.json";
}

TEST_F(SceneSchema, EveryShippedSceneValidatesAndNamesIt) {
  const auto scenes = shipped_scenes();
  ASSERT_GT(scenes.size(), 30u);
  for (const fs::path& file : scenes) {
    const Json scene = Json::parse(read_text(file));
    for (const std::string& p : problems_of(scene, committed_)) ADD_FAILURE() << file << ": " << p;
    // "$schema" is relative to the scene's own folder.
    ASSERT_TRUE(scene.contains("$schema")) << file;
    EXPECT_TRUE(fs::equivalent(file.parent_path() / scene["$schema"].get<std::string>(),
                               kSource / "scenes/scene.schema.json"))
        << file << " names " << scene["$schema"];
  }
}

// The schema holds what it should: the type, bounds, choices and required keys the parser reads with, and
// no bound that follows the scene's size.
TEST_F(SceneSchema, KeysCarryTheParsersTypesBoundsAndChoices) {
  const Json& props = committed_["properties"];
  EXPECT_EQ(committed_["additionalProperties"], false);
  EXPECT_EQ(props["time"]["properties"]["fps"], Json::parse(R"({"type": "number", "minimum": 1.0, "maximum": 10000.0, "default": 30.0})"));
  const Json& objective = props["objectives"]["items"];
  EXPECT_EQ(objective["required"], Json::parse(R"(["frame", "type"])"));
  EXPECT_EQ(objective["properties"]["type"]["enum"],
            Json::parse(R"(["position", "velocity", "center_of_mass", "shape", "arch", "height"])"));
  EXPECT_EQ(objective["properties"]["frame"], Json::parse(R"({"type": "integer", "minimum": 0})"));
  // Indices have no upper bound in the schema (it depends on the scene's particle count).
  const Json& particle_forms = objective["properties"]["particles"];
  ASSERT_TRUE(particle_forms.contains("anyOf")) << particle_forms.dump();
  const auto indices = std::find_if(particle_forms["anyOf"].begin(), particle_forms["anyOf"].end(),
                                    [](const Json& form) { return form.value("type", "") == "array"; });
  ASSERT_NE(indices, particle_forms["anyOf"].end()) << particle_forms.dump();
  EXPECT_FALSE((*indices)["items"].contains("maximum"));
  EXPECT_EQ(props["cloth"]["properties"]["pins"]["anyOf"].size(), 3u);  // indices, a named set, a selector or box
  EXPECT_EQ(props["cloth"]["properties"]["colliders"]["items"]["required"], Json::parse(R"(["type"])"));
  EXPECT_FALSE(props["character"].contains("required") &&
               std::find(props["character"]["required"].begin(), props["character"]["required"].end(), "time") !=
                   props["character"]["required"].end());
  EXPECT_EQ(props["character"]["required"], Json::parse(R"(["file"])"));
  EXPECT_EQ(props["$schema"]["type"], "string");
}

// The mistakes a schema can see are found, at the same pointer the parser names.
TEST_F(SceneSchema, RejectsWhatTheParserRejects) {
  const Json good = Json::parse(read_text(kSource / "scenes/square.json"));
  ASSERT_TRUE(problems_of(good, committed_).empty());
  struct Case {
    const char* pointer;
    Json value;
    const char* problem;
  };
  const std::vector<Case> cases = {
      {"/flock/avoidance/radiu", 1.0, "/flock/avoidance/radiu: not allowed"},
      {"/flock/avoidance/radius", -1.0, "/flock/avoidance/radius: below minimum"},
      {"/time/frames", "100", "/time/frames: expected integer"},
      {"/time/frames", 2.5, "/time/frames: expected integer"},
      {"/controls/kind", "per_second", "/controls/kind: not one of"},
      {"/render/background", Json::array({0, 0}), "/render/background: too few items"},
  };
  for (const Case& c : cases) {
    Json bad = good;
    bad[Json::json_pointer(c.pointer)] = c.value;
    const auto problems = problems_of(bad, committed_);
    ASSERT_EQ(problems.size(), 1u) << c.pointer;
    EXPECT_EQ(problems.front().rfind(c.problem, 0), 0u) << problems.front();
    EXPECT_THROW(parse_scene(bad.dump(), "bad.json"), InputError) << c.pointer;
  }
  Json missing = good;
  missing["objectives"][0].erase("frame");
  EXPECT_EQ(problems_of(missing, committed_), std::vector<std::string>{"/objectives/0: missing required \"frame\""});
  EXPECT_THROW(parse_scene(missing.dump(), "bad.json"), InputError);
}

// A mesh cloth's selectors come in forms that do not mix: a named set {"group"}, a rest-space box with both
// "min" and "max", or (keyframe particles) grid rows and columns; a hole is a polygon or a circle. What mixes
// two forms, or leaves out a key its form requires, does not validate, and the parser refuses it too.
TEST_F(SceneSchema, SelectorFormsDoNotMix) {
  const Json good = Json::parse(read_text(kSource / "scenes/robustness/poncho.json"));
  ASSERT_TRUE(problems_of(good, committed_).empty());
  const Json box = good["cloth"]["pins"];
  struct Case {
    const char* pointer;
    Json value;
  };
  const std::vector<Case> cases = {
      {"/cloth/pins", Json{{"group", "collar"}, {"min", box["min"]}, {"max", box["max"]}}},
      {"/cloth/pins", Json{{"min", box["min"]}}},
      {"/cloth/pins", Json::object()},
      {"/objectives/0/particles", Json{{"group", "hem"}, {"row", 0}}},
      {"/objectives/0/particles", Json{{"max", box["max"]}, {"column", 1}}},
      {"/objectives/0/particles", Json{{"min", box["min"]}, {"max", box["max"]}, {"u", {0, 1}}}},
  };
  for (const Case& c : cases) {
    Json bad = good;
    bad[Json::json_pointer(c.pointer)] = c.value;
    const auto problems = problems_of(bad, committed_);
    ASSERT_EQ(problems.size(), 1u) << c.pointer << " " << c.value.dump();
    EXPECT_EQ(problems.front(), std::string(c.pointer) + ": matches none of anyOf") << c.value.dump();
    EXPECT_THROW(parse_scene(bad.dump(), kSource / "scenes/robustness/poncho.json"), InputError) << c.value.dump();
  }
  // Each form alone still validates.
  for (const Json& form : {Json{{"group", "collar"}}, box}) {
    Json ok = good;
    ok["cloth"]["pins"] = form;
    EXPECT_TRUE(problems_of(ok, committed_).empty()) << form.dump();
  }
  const Json flock = Json::parse(read_text(kSource / "scenes/robustness/flock-arrow.json"));
  Json both = flock;
  both["objectives"][0]["holes"] =
      Json::array({Json{{"polygon", {{-1, 5}, {1, 5}, {0, 6}}}, {"circle", {{"center", {0, 8}}, {"radius", 0.5}}}}});
  EXPECT_EQ(problems_of(both, committed_), std::vector<std::string>{"/objectives/0/holes/0: matches none of anyOf"});
  EXPECT_THROW(parse_scene(both.dump(), kSource / "scenes/robustness/flock-arrow.json"), InputError);
}

// The schema states the parser's rule of exactly one system.
TEST_F(SceneSchema, StatesExactlyOneOfFlockAndCloth) {
  const Json flock = Json::parse(read_text(kSource / "scenes/square.json"));
  Json both = flock, neither = flock;
  both["cloth"] = Json::object();
  neither.erase("flock");
  neither.erase("objectives");
  EXPECT_EQ(problems_of(both, committed_), std::vector<std::string>{"/: matches 2 of oneOf"});
  EXPECT_EQ(problems_of(neither, committed_), std::vector<std::string>{"/: matches 0 of oneOf"});
  EXPECT_THROW(parse_scene(both.dump(), "bad.json"), InputError);
  EXPECT_THROW(parse_scene(neither.dump(), "bad.json"), InputError);
}

// "$schema" is read and ignored; a misspelling of it is an unknown key like any other.
TEST_F(SceneSchema, ParserIgnoresSchemaKeyAndStillRejectsUnknownKeys) {
  Json scene = Json::parse(read_text(kSource / "scenes/square.json"));
  scene["$schema"] = "https://example.org/anything.json";
  EXPECT_NO_THROW(parse_scene(scene.dump(), "square.json"));
  scene.erase("$schema");
  scene["$shema"] = "scene.schema.json";
  try {
    parse_scene(scene.dump(), "square.json");
    ADD_FAILURE() << "an unknown top-level key was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "square.json: /$shema: unknown key (check its spelling; see README 'Scene files')");
  }
  scene.erase("$shema");
  scene["$schema"] = 3;
  EXPECT_THROW(parse_scene(scene.dump(), "square.json"), InputError);
}

}  // namespace
}  // namespace kf
