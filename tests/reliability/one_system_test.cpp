// A scene holds exactly one system: with both `flock` and `cloth` (each valid on its own) the real binary
// refuses it in every command that reads a scene, and the schema it prints states the same rule, so an
// editor that checks scenes against it refuses the scene too.
#include <nlohmann/json.hpp>

#include "cli_harness.h"
#include "core/error.h"

namespace kf::reliability {
namespace {

// The small flock scene with the small cloth scene's (valid) cloth block added.
std::string both_systems_scene() {
  auto scene = nlohmann::json::parse(small_flock_scene());
  scene["cloth"] = nlohmann::json::parse(small_cloth_scene()).at("cloth");
  return scene.dump(2);
}

class OneSystemCli : public TempDirTest, public ::testing::WithParamInterface<const char*> {};

TEST_P(OneSystemCli, SceneWithBothFlockAndClothIsRefusedWithNothingWritten) {
  write("s.json", both_systems_scene());
  const auto before = list_tree(dir_);
  const CliResult r = run_bounded(std::string(GetParam()) + " s.json", dir_);
  EXPECT_EQ(r.code, kExitInput) << r.output;
  EXPECT_EQ(r.output, "keyframe: error: s.json: /: expected exactly one of \"flock\" or \"cloth\"\n");
  EXPECT_EQ(list_tree(dir_), before);
}

INSTANTIATE_TEST_SUITE_P(Commands, OneSystemCli, ::testing::Values("inspect", "simulate", "optimize"),
                         [](const auto& info) { return std::string(info.param); });

class OneSystemSchema : public TempDirTest {};

TEST_F(OneSystemSchema, PrintedSchemaRequiresExactlyOneOfFlockAndCloth) {
  const CliResult r = run_in("'" KEYFRAME_BINARY "' schema 2>/dev/null", dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  const auto schema = nlohmann::json::parse(r.output);
  const auto one_of = nlohmann::json::parse(R"([{"required": ["flock"]}, {"required": ["cloth"]}])");
  EXPECT_EQ(schema.at("oneOf"), one_of);
  // Neither system is required on its own (that would make the other one impossible) ...
  for (const auto& key : schema.value("required", nlohmann::json::array())) {
    EXPECT_NE(key, "flock");
    EXPECT_NE(key, "cloth");
  }
  // ... and both are described, so a scene with one of them is checked key by key.
  EXPECT_TRUE(schema.at("properties").contains("flock"));
  EXPECT_TRUE(schema.at("properties").contains("cloth"));
  EXPECT_NE(schema.at("description").get<std::string>().find("exactly one of \"flock\" or \"cloth\""),
            std::string::npos);
}

}  // namespace
}  // namespace kf::reliability
