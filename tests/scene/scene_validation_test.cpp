// Malformed scenes: each gives one line naming the file, the JSON pointer and what was expected.
#include <gtest/gtest.h>

#include "core/error.h"
#include "scene/scene.h"

namespace kf {
namespace {

const char* kGood = R"({
  "time": {"fps": 30, "frames": 20},
  "cloth": {"nx": 3, "ny": 3},
  "objectives": [{"type": "position", "frame": 10, "particles": [0], "targets": [[0, 1, 0]]}],
  "controls": {"kind": "per_frame", "alpha": 0.001},
  "optimizer": {"max_evaluations": 5}
})";

struct Case {
  const char* name;
  std::string text;
  std::string message;  // expected message after "bad.json: "
};

std::string replace(std::string s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return s.replace(at, from.size(), to);
}

std::vector<Case> cases() {
  const std::string g = kGood;
  return {
      {"not_json", "{\"time\": ", "not valid JSON"},
      {"truncated", g.substr(0, g.size() / 2), "not valid JSON"},
      {"root_not_object", "[1, 2]", "/: expected an object, got array"},
      {"no_system", replace(g, R"("cloth": {"nx": 3, "ny": 3},)", ""), "/: expected exactly one of \"flock\" or \"cloth\""},
      {"unknown_top_key", replace(g, R"("time")", R"("tmie": 1, "time")"), "/tmie: unknown key"},
      {"unknown_nested_key", replace(g, R"("fps": 30)", R"("fps": 30, "fsp": 2)"), "/time/fsp: unknown key"},
      {"fps_string", replace(g, R"("fps": 30)", R"("fps": "30")"), "/time/fps: expected a number, got string"},
      {"fps_negative", replace(g, R"("fps": 30)", R"("fps": -30)"), "/time/fps: expected a number in [1, 10000], got -30"},
      {"frames_fraction", replace(g, R"("frames": 20)", R"("frames": 2.5)"), "/time/frames: expected an integer"},
      {"frames_zero", replace(g, R"("frames": 20)", R"("frames": 0)"), "/time/frames: expected an integer in [1, 1000000], got 0"},
      {"keyframe_after_end", replace(g, R"("frame": 10)", R"("frame": 21)"), "/objectives/0/frame: expected an integer in [0, 20], got 21"},
      {"objective_type", replace(g, R"("type": "position")", R"("type": "posture")"), "/objectives/0/type: expected one of"},
      {"particle_out_of_range", replace(g, R"("particles": [0])", R"("particles": [9])"), "/objectives/0/particles/0: expected an integer in [0, 8], got 9"},
      {"target_wrong_shape", replace(g, R"([[0, 1, 0]])", R"([[0, 1]])"), "/objectives/0/targets/0: expected [x, y, z]"},
      {"target_count", replace(g, R"("particles": [0], "targets": [[0, 1, 0]])", R"("particles": [0, 1, 2], "targets": [[0, 1, 0], [1, 1, 1]])"), "/objectives/0/targets: expected 1 target or one per particle (3), got 2"},
      {"missing_targets", replace(g, R"(, "targets": [[0, 1, 0]])", ""), "/objectives/0/targets: required key is missing"},
      {"shape_on_cloth", replace(g, R"("type": "position")", R"("type": "shape", "polygon": [[0,0],[1,0],[1,1]])"), "/objectives/0/type: \"shape\" keyframes are for flocks"},
      {"controls_kind", replace(g, R"("kind": "per_frame")", R"("kind": "per_second")"), "/controls/kind: expected one of \"per_step\", \"per_frame\", \"initial_velocity\", \"initial_rigid_velocity\", \"initial_lattice_velocity\", got \"per_second\""},
      {"alpha_negative", replace(g, R"("alpha": 0.001)", R"("alpha": -1)"), "/controls/alpha: expected a number in [0, 1e+06], got -1"},
      {"objectives_not_array", replace(g, R"("objectives": [)", R"("objectives": {"a": [)") , "not valid JSON"},
      {"objective_not_object", replace(g, R"([{"type": "position", "frame": 10, "particles": [0], "targets": [[0, 1, 0]]}])", "[3]"), "/objectives/0: expected an object, got number 3"},
      {"evaluations_negative", replace(g, R"("max_evaluations": 5)", R"("max_evaluations": -5)"), "/optimizer/max_evaluations: expected an integer in [0, 1000000], got -5"},
      {"nan_literal", replace(g, R"("alpha": 0.001)", R"("alpha": NaN)"), "not valid JSON"},
      {"huge_number", replace(g, R"("alpha": 0.001)", R"("alpha": 1e999)"), "not valid JSON: number overflow parsing '1e999'"},
      {"stage_controls_per_frame", replace(g, R"("max_evaluations": 5)", R"("schedule": [{"substeps": 1, "controls": {"kind": "initial_rigid_velocity"}}, {"substeps": 1}])"), "/optimizer/schedule/0/controls/kind: expected one of \"per_frame\", \"per_frame_lattice\", got \"initial_rigid_velocity\""},
      {"stage_controls_per_step", replace(replace(g, R"("kind": "per_frame")", R"("kind": "per_step")"), R"("max_evaluations": 5)", R"("schedule": [{"substeps": 1, "controls": {"kind": "per_frame_lattice"}}, {"substeps": 1}])"), "/optimizer/schedule/0/controls: a stage's own controls only with the scene's controls.kind \"initial_velocity\" or \"per_frame\""},
      {"scene_lattice_forces", replace(g, R"("kind": "per_frame")", R"("kind": "per_frame_lattice")"), "/controls/kind: expected one of \"per_step\", \"per_frame\", \"initial_velocity\", \"initial_rigid_velocity\", \"initial_lattice_velocity\", got \"per_frame_lattice\""},
      {"stage_controls_last", replace(replace(g, R"("kind": "per_frame")", R"("kind": "initial_velocity")"), R"("max_evaluations": 5)", R"("schedule": [{"substeps": 1, "controls": {"kind": "initial_rigid_velocity"}}])"), "/optimizer/schedule/0/controls: the last stage uses the scene's controls (no \"controls\")"},
      {"stage_controls_kind", replace(replace(g, R"("kind": "per_frame")", R"("kind": "initial_velocity")"), R"("max_evaluations": 5)", R"("schedule": [{"substeps": 1, "controls": {"kind": "per_step"}}, {"substeps": 1}])"), "/optimizer/schedule/0/controls/kind: expected one of \"initial_velocity\", \"initial_rigid_velocity\", \"initial_lattice_velocity\", got \"per_step\""},
      {"transverse_ramp_zero", replace(g, R"("cloth": {"nx": 3, "ny": 3})", R"("cloth": {"nx": 3, "ny": 3, "transverse_ramp": 0})"), "/cloth/transverse_ramp: expected a number in [0.0001, 1], got 0"},
      {"theta_below_half", replace(g, R"("cloth": {"nx": 3, "ny": 3})", R"("cloth": {"nx": 3, "ny": 3, "theta": 0.4})"), "/cloth/theta: expected a number in [0.5, 1], got 0.4"},
      {"seed_type", replace(g, R"("time")", R"("seed": "one", "time")"), "/seed: expected an integer, got string"},
  };
}

class MalformedScene : public ::testing::TestWithParam<Case> {};

TEST_P(MalformedScene, GivesItsSpecificError) {
  const Case& c = GetParam();
  try {
    parse_scene(c.text, "bad.json");
    FAIL() << c.name << " was accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("bad.json: ", 0), 0u) << what;
    EXPECT_NE(what.find(c.message), std::string::npos) << c.name << ": got \"" << what << "\"";
    EXPECT_EQ(what.find('\n'), std::string::npos) << "one line only";
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, MalformedScene, ::testing::ValuesIn(cases()),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(SceneValidation, GoodSceneLoads) {
  const Scene s = parse_scene(kGood, "good.json");
  EXPECT_EQ(s.particles(), 9);
  EXPECT_EQ(s.time.steps(), 20);
  EXPECT_EQ(s.objectives.size(), 1u);
  EXPECT_EQ(s.name, "good");
}

}  // namespace
}  // namespace kf
