// What a user writing a character scene is told: errors that name the scene's field and the names the mesh
// file has, the animation playing at its own rate when "time" is absent, and warnings for an animation
// shorter than the scene and for a cape edge laid out away from its anchors.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "core/error.h"
#include "core/warnings.h"
#include "scene/scene.h"
#include "sim/character/scene_character.h"
#include "sim/make_system.h"
#include "character_test_util.h"

namespace kf {
namespace {

// A small cape on the shipped character; `character` is pasted into the character block after "file".
std::string scene_with(const std::string& character, int frames = 4, const std::string& cloth_origin = "[-0.215, -0.03, -0.3]") {
  return R"({"time": {"fps": 30, "frames": )" + std::to_string(frames) + R"(},
    "cloth": {"nx": 5, "ny": 4, "width": 0.43, "height": 0.5, "origin": )" + cloth_origin + R"(, "pins": "top_edge"},
    "character": {"file": ")" + test::character_asset().string() + "\"" + character + "}}";
}

std::string error_of(const std::string& scene_text) {
  try {
    const Scene scene = parse_scene(scene_text, "cape.json");
    make_system(scene);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

int warnings_containing(const std::string& text) {
  const auto w = warnings_so_far();
  return int(std::count_if(w.begin(), w.end(), [&](const std::string& s) { return s.find(text) != std::string::npos; }));
}

TEST(CharacterAuthoring, WrongMeshNameNamesTheFieldAndTheMeshesThereAre) {
  const std::string e = error_of(scene_with(R"(, "anchors": {"mesh": "Body", "points": [[-0.1, 0.45, -0.25], [0.1, 0.45, -0.25]]})"));
  EXPECT_NE(e.find("cape.json: /character/anchors/mesh: no mesh named 'Body' in "), std::string::npos) << e;
  EXPECT_NE(e.find("BCN_Epileptic.X (its meshes: "), std::string::npos) << e;
  for (const char* mesh : {"'Torso'", "'Head'", "'Legs'"}) EXPECT_NE(e.find(mesh), std::string::npos) << e;
}

TEST(CharacterAuthoring, WrongNodeNameNamesTheFieldAndTheBonesThereAre) {
  const std::string e = error_of(scene_with(R"(, "anchors": {"nodes": ["B_Clavicle_Left", "Shoulder_R"]})"));
  EXPECT_NE(e.find("cape.json: /character/anchors/nodes/1: no node named 'Shoulder_R' in "), std::string::npos) << e;
  EXPECT_NE(e.find("(its bones: "), std::string::npos) << e;
  EXPECT_NE(e.find("'B_Clavicle_Right'"), std::string::npos) << e;  // the name the user meant is listed
}

TEST(CharacterAuthoring, AnchorsNeedPointsOrNodes) {
  const std::string neither = error_of(scene_with(R"(, "anchors": {"mesh": "Torso"})"));
  EXPECT_NE(neither.find("cape.json: /character/anchors: expected exactly one of \"points\""), std::string::npos) << neither;
  const std::string both = error_of(
      scene_with(R"(, "anchors": {"points": [[0, 0, 0], [1, 0, 0]], "nodes": ["B_Clavicle_Left", "B_Clavicle_Right"]})"));
  EXPECT_NE(both.find("/character/anchors: expected exactly one of"), std::string::npos) << both;
}

TEST(CharacterAuthoring, FileAndAnimationErrorsNameTheField) {
  std::string s = scene_with(R"(, "animation": 3)");
  std::string e = error_of(s);
  EXPECT_NE(e.find("cape.json: /character/animation: "), std::string::npos) << e;
  EXPECT_NE(e.find("animation 3 requested, file has 1"), std::string::npos) << e;
  s = scene_with(R"(, "anchors": {"nodes": ["B_Clavicle_Left", "B_Clavicle_Right"]})");
  s.replace(s.find("BCN_Epileptic.X"), 15, "Missing.X");
  e = error_of(s);
  EXPECT_NE(e.find("cape.json: /character/file: "), std::string::npos) << e;
  EXPECT_NE(e.find("no such mesh file "), std::string::npos) << e;
  EXPECT_NE(e.find("Missing.X"), std::string::npos) << e;
}

// Without "time" the body is not frozen: frame f plays the animation at f / fps seconds.
TEST(CharacterAuthoring, WithoutTimeTheAnimationPlaysAtItsOwnRate) {
  const Scene scene = parse_scene(scene_with("", 30), "cape.json");
  ASSERT_TRUE(scene.character.has_value());
  EXPECT_DOUBLE_EQ(animation_time(*scene.character, 0), 0.0);
  EXPECT_DOUBLE_EQ(animation_time(*scene.character, 15), 0.5);
  EXPECT_DOUBLE_EQ(animation_time(*scene.character, 4), 4.0 / 30);
  // The body's pose moves: the crouch starts within the first second.
  Character body = load_character(*scene.character, scene.time.frames);
  VecX at0, at30;
  pose_at_frame(body, *scene.character, 0, at0);
  pose_at_frame(body, *scene.character, 30, at30);
  EXPECT_GT((at30 - at0).cwiseAbs().maxCoeff(), 0.05);
}

// A "time" block that holds one instant and no root motion: the body never moves, and the user is told.
TEST(CharacterAuthoring, FrozenAnimationWarns) {
  const Scene frozen = parse_scene(scene_with(R"(, "time": [[0, 0.5], [4, 0.5]])"), "frozen.json");
  load_character(*frozen.character, frozen.time.frames);
  EXPECT_EQ(warnings_containing("frozen.json: /character/time: every key is at 0.5 s of the animation and there is no "
                                "root motion: the body stays in one pose for the whole scene (leave \"time\" out"),
            1);
  const Scene moving = parse_scene(scene_with(R"(, "time": [[0, 0.5], [4, 0.6]])"), "moving.json");
  load_character(*moving.character, moving.time.frames);
  EXPECT_EQ(warnings_containing("moving.json"), 0);
}

// A scene longer than the animation: the body holds its last pose from the frame the animation ends, and
// the user is told which frame that is.
TEST(CharacterAuthoring, AnimationShorterThanTheSceneWarns) {
  const std::string text = "ends at 3.3 s, before the scene's last frame (frame 120 at 4 s): the body holds its last "
                           "pose from frame 100 on";
  const Scene long_scene = parse_scene(scene_with("", 120), "long.json");
  load_character(*long_scene.character, long_scene.time.frames);
  EXPECT_EQ(warnings_containing(text), 1);
  EXPECT_EQ(warnings_containing("long.json: /character: the animation of BCN_Epileptic.X ends at 3.3 s"), 1);
  // 99 frames end at 3.3 s: no warning for that scene.
  const Scene fits = parse_scene(scene_with("", 99), "fits.json");
  load_character(*fits.character, fits.time.frames);
  EXPECT_EQ(warnings_containing("fits.json"), 0);
  // Past the end by round-off (30 microseconds): the same pose, no warning; by 10 ms: the warning.
  const Scene roundoff = parse_scene(scene_with(R"(, "time": [[0, 0], [99, 3.30003]])", 99), "roundoff.json");
  load_character(*roundoff.character, roundoff.time.frames);
  EXPECT_EQ(warnings_containing("roundoff.json"), 0);
  const Scene past = parse_scene(scene_with(R"(, "time": [[0, 0], [99, 3.31]])", 99), "past.json");
  load_character(*past.character, past.time.frames);
  EXPECT_EQ(warnings_containing("past.json: /character: the animation of BCN_Epileptic.X ends at 3.3 s, before the "
                                "scene's last frame (frame 99 at 3.31 s): the body holds its last pose from frame 99 on"),
            1);
}

// The sheet laid out 0.6 m below the shoulders: its pinned edge would jump there at frame 0.
TEST(CharacterAuthoring, PinnedEdgeFarFromItsAnchorsWarns) {
  const std::string text = "snap.json: /character/anchors: the cape's pinned top edge starts up to ";
  make_system(parse_scene(scene_with("", 4, "[-0.215, -0.63, -0.3]"), "snap.json"));
  ASSERT_EQ(warnings_containing(text), 1);
  const auto w = warnings_so_far();
  const std::string& msg = *std::find_if(w.begin(), w.end(), [&](const std::string& s) { return s.find(text) == 0; });
  const double jump = std::stod(msg.substr(text.size()));
  EXPECT_GT(jump, 0.6);
  EXPECT_LT(jump, 0.7);
  EXPECT_NE(msg.find("lay the top edge along the anchors"), std::string::npos) << msg;
  // The cape tests' layout, along the shoulders: no warning.
  make_system(parse_scene(scene_with("", 4), "laid.json"));
  EXPECT_EQ(warnings_containing("laid.json"), 0);
}

}  // namespace
}  // namespace kf
