// The Blender add-on (scripts/blender/keyframe_cloth.py) in Debian's Blender, headless, against the real
// keyframe binary: tests/blender/solve_shot.py builds and solves a shot and checks it; the README's install
// command enables the add-on in a fresh user configuration. scripts/setup installs blender for the tests;
// without it these skip, except under CI where they fail.
#include <gtest/gtest.h>

#include <cstdlib>

#include "../reliability/cli_harness.h"

namespace kf::reliability {
namespace {

bool have_blender() {
  if (run_in("command -v blender >/dev/null", fs::temp_directory_path()).code == 0) return true;
  if (std::getenv("CI")) ADD_FAILURE() << "blender is not installed (scripts/setup installs it)";
  return false;
}

// `blender -b ARGS` without the user's own preferences, scripts or startup file (ENV: extra variables).
CliResult blender(const std::string& env, const std::string& args, const fs::path& cwd) {
  return run_in("timeout -s KILL 110 env " + env + " blender -b --python-exit-code 1 " + args, cwd);
}

class BlenderAddon : public TempDirTest {};

TEST_F(BlenderAddon, SolvesAShotPlaysItBackAndReportsAMiss) {
  if (!have_blender()) GTEST_SKIP() << "blender not installed";
  const CliResult r = blender("KEYFRAME_BINARY='" KEYFRAME_BINARY "'",
                              "--factory-startup --python '" KEYFRAME_SOURCE_DIR "/tests/blender/solve_shot.py' -- '" +
                                  dir_.string() + "'",
                              dir_);
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("BLENDER ADD-ON CHECKS PASSED"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(dir_ / "Sheet.obj"));
  EXPECT_TRUE(fs::exists(dir_ / "Sheet-run/export/Sheet.blender.pc2"));
}

TEST_F(BlenderAddon, InstallCommandEnablesItInTheUsersPreferences) {
  if (!have_blender()) GTEST_SKIP() << "blender not installed";
  const std::string user = "BLENDER_USER_SCRIPTS='" + (dir_ / "scripts").string() + "' BLENDER_USER_CONFIG='" +
                           (dir_ / "config").string() + "'";
  const CliResult install = blender(user, "--python scripts/blender/install.py", KEYFRAME_SOURCE_DIR);
  ASSERT_EQ(install.code, 0) << install.output;
  EXPECT_TRUE(fs::exists(dir_ / "scripts/addons/keyframe_cloth.py"));
  // A new Blender with that configuration has it enabled, its panel and its operators registered.
  const CliResult check = blender(
      user,
      "--python-expr \"import bpy; assert 'keyframe_cloth' in bpy.context.preferences.addons; "
      "assert hasattr(bpy.types, 'KEYFRAME_PT_panel') and hasattr(bpy.ops.keyframe, 'solve'); print('ENABLED')\"",
      dir_);
  EXPECT_EQ(check.code, 0) << check.output;
  EXPECT_NE(check.output.find("ENABLED"), std::string::npos) << check.output;
  // Without the install the same check fails (so it can fail).
  const std::string fresh = "BLENDER_USER_SCRIPTS='" + (dir_ / "none").string() + "' BLENDER_USER_CONFIG='" +
                            (dir_ / "none").string() + "'";
  EXPECT_NE(blender(fresh, "--python-expr \"import bpy; assert 'keyframe_cloth' in bpy.context.preferences.addons\"",
                    dir_).code,
            0);
}

}  // namespace
}  // namespace kf::reliability
