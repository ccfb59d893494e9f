// Loading the character: counts of the asset and one-line errors for bad files.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>

#include "core/error.h"
#include "sim/character/character.h"
#include "character_test_util.h"

namespace kf {
namespace {

// Expects InputError whose message names `file`.
void expect_input_error_naming(const std::filesystem::path& file) {
  try {
    Character c(file);
    FAIL() << "loading " << file << " should have failed";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
  }
}

TEST(CharacterLoad, AssetHasTheDocumentedShape) {
  Character c(test::character_asset());
  EXPECT_EQ(c.vertex_count(), 3014);
  EXPECT_EQ(c.triangle_count(), 5126);
  EXPECT_EQ(c.bones().size(), 54u);
  EXPECT_EQ(c.mesh_names().size(), 3u);
  EXPECT_NEAR(c.duration(), 3.3, 1e-12);
  // Y up, 1.814 m tall.
  const VecX& x = c.bind_vertices();
  double lo = 1e9, hi = -1e9;
  for (int v = 0; v < c.vertex_count(); ++v) lo = std::min(lo, x[3 * v + 1]), hi = std::max(hi, x[3 * v + 1]);
  EXPECT_NEAR(hi - lo, 1.814, 2e-3);
  // Faces +Z: toes are in front of the ankles.
  const double toe_z = c.node_world(c.node_index("B_Toe_Left"), 0.0).translation().z();
  const double ankle_z = c.node_world(c.node_index("B_Ankle_Left"), 0.0).translation().z();
  EXPECT_GT(toe_z - ankle_z, 0.1);
  // Every vertex's weights sum to one.
  for (int v = 0; v < c.vertex_count(); ++v) {
    double sum = 0.0;
    for (int k = 0; k < Character::kMaxInfluences; ++k) sum += c.influence_weights()[Character::kMaxInfluences * v + k];
    ASSERT_NEAR(sum, 1.0, 1e-5) << "vertex " << v;
  }
}

TEST(CharacterLoad, MissingFileIsAnInputErrorNamingIt) {
  test::TempDir dir;
  expect_input_error_naming(dir.path() / "no_such_character.X");
}

TEST(CharacterLoad, TruncatedFileIsAnInputErrorNamingIt) {
  test::TempDir dir;
  std::ifstream in(test::character_asset(), std::ios::binary);
  const std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(all.size(), 100000u);
  const auto truncated = dir.path() / "truncated.X";
  std::ofstream(truncated, std::ios::binary) << all.substr(0, all.size() / 3);
  expect_input_error_naming(truncated);
}

TEST(CharacterLoad, GarbageIsAnInputErrorNamingIt) {
  test::TempDir dir;
  const auto garbage = dir.path() / "garbage.X";
  std::ofstream(garbage) << "this is not a mesh\n";
  expect_input_error_naming(garbage);
}

// A file without animation (or bones) is a still body: its vertices follow their node, duration 0.
TEST(CharacterLoad, StaticMeshWithoutAnimationLoadsAsAStillBody) {
  test::TempDir dir;
  const auto obj = dir.path() / "triangle.obj";
  std::ofstream(obj) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  Character c(obj);
  EXPECT_EQ(c.vertex_count(), 3);
  EXPECT_EQ(c.duration(), 0.0);
  VecX at0, at1;
  c.pose(0.0, at0);
  c.pose(1.0, at1);
  EXPECT_EQ(at0, at1);
  EXPECT_LT((at0 - c.bind_vertices()).norm(), 1e-12);
  CharacterOptions later;
  later.animation = 1;
  EXPECT_THROW(Character(obj, later), InputError);  // it has no animation 1
}

}  // namespace
}  // namespace kf
