// Malformed scenes, run directories and unwritable outputs through the real `keyframe` binary: each gives
// its own one-line message and exit code, and writes nothing (no run directory, no stray files).
#include <sys/mount.h>
#include <sys/stat.h>

#include <cstring>

#include "core/error.h"
#include "cli_harness.h"

namespace kf::reliability {
namespace {

struct BadScene {
  const char* name;      // test name suffix
  const char* command;   // subcommand run on s.json
  std::string scene;     // contents of s.json
  std::string message;   // the whole expected output after "keyframe: error: "
};

// A valid flock scene with `flock` as its flock block and `extra` appended at the top level.
std::string flock_with(const std::string& flock, const std::string& extra = "") {
  return R"({"time": {"frames": 10}, "flock": )" + flock + extra + "}";
}
std::string cloth_with(const std::string& cloth, const std::string& extra = "") {
  return R"({"time": {"frames": 10}, "cloth": )" + cloth + extra + "}";
}

const BadScene kBadScenes[] = {
    // Not JSON at all, or not a scene object.
    {"EmptyFile", "simulate", "",
     "s.json: not valid JSON: parse error at line 1, column 1: syntax error while parsing value - unexpected "
     "end of input; expected '[', '{', or a literal"},
    {"TruncatedJson", "simulate", R"({"time": {"fps": 30)",
     "s.json: not valid JSON: parse error at line 1, column 20: syntax error while parsing object - unexpected "
     "end of input; expected '}'"},
    {"TrailingGarbage", "simulate", R"({"flock": {}} x)",
     "s.json: not valid JSON: parse error at line 1, column 15: syntax error while parsing value - invalid "
     "literal; last read: '\"flock\": {}} x'; expected end of input"},
    {"NaNLiteral", "optimize", R"({"flock": {"mass": NaN}})",
     "s.json: not valid JSON: parse error at line 1, column 20: syntax error while parsing value - invalid "
     "literal; last read: '\"mass\": N'"},
    {"TopLevelArray", "simulate", "[1, 2]", "s.json: /: expected an object, got array [1,2]"},
    {"TimeIsANumber", "simulate", R"({"time": 3, "flock": {}})", "s.json: /time: expected an object, got number 3"},
    // Empty or ambiguous systems.
    {"NoSystem", "simulate", R"({"time": {"frames": 10}})",
     "s.json: /: expected exactly one of \"flock\" or \"cloth\""},
    {"BothSystems", "simulate", R"({"flock": {}, "cloth": {}})",
     "s.json: /: expected exactly one of \"flock\" or \"cloth\""},
    {"ZeroAgents", "optimize", flock_with(R"({"agents": 0})"),
     "s.json: /flock/agents: expected an integer in [1, 1000000], got 0"},
    {"NegativeAgents", "simulate", flock_with(R"({"agents": -5})"),
     "s.json: /flock/agents: expected an integer in [1, 1000000], got -5"},
    {"FractionalAgents", "simulate", flock_with(R"({"agents": 2.5})"),
     "s.json: /flock/agents: expected an integer, got number 2.5"},
    {"AgentsAsString", "simulate", flock_with(R"({"agents": "ten"})"),
     "s.json: /flock/agents: expected an integer, got string \"ten\""},
    // Values that make no physical sense.
    {"NegativeFlockMass", "simulate", flock_with(R"({"mass": -1})"),
     "s.json: /flock/mass: expected a number in [1e-06, 1e+06], got -1"},
    {"ZeroFlockMass", "gradcheck", flock_with(R"({"mass": 0})"),
     "s.json: /flock/mass: expected a number in [1e-06, 1e+06], got 0"},
    {"OverflowingFlockMass", "simulate", flock_with(R"({"mass": 1e999})"),
     "s.json: not valid JSON: number overflow parsing '1e999'"},
    {"ZeroAvoidanceRadius", "simulate", flock_with(R"({"avoidance": {"radius": 0}})"),
     "s.json: /flock/avoidance/radius: expected a number in [0.001, 10000], got 0"},
    {"NegativeDrag", "simulate", flock_with(R"({"drag": {"strength": -2}})"),
     "s.json: /flock/drag/strength: expected a number in [0, 1e+06], got -2"},
    {"SpawnOffGround", "simulate", flock_with(R"({"spawn": {"center": [0, 1, 0]}})"),
     "s.json: /flock/spawn/center: expected [x, 0, z] (flocks live on the ground plane y = 0), got y = 1"},
    {"SpawnDiscTooSmall", "simulate", flock_with(R"({"agents": 500, "spawn": {"radius": 1}})"),
     "s.json: /flock/spawn/radius: too small for 500 agents at least 0.9 m apart (0.6 x avoidance radius); need "
     "at least 11.59, got 1"},
    {"ZeroSubsteps", "simulate", R"({"time": {"substeps": 0}, "flock": {}})",
     "s.json: /time/substeps: expected an integer in [1, 10000], got 0"},
    {"ZeroFrames", "simulate", R"({"time": {"frames": 0}, "flock": {}})",
     "s.json: /time/frames: expected an integer in [1, 1000000], got 0"},
    {"TooManySteps", "simulate", R"({"time": {"frames": 1000000, "substeps": 100}, "flock": {}})",
     "s.json: /time: too many steps (frames x substeps must be at most 1e7)"},
    {"CharacterMeshMissing", "simulate", cloth_with("{}", R"(, "character": {"file": "nosuch.X"})"),
     "s.json: /character/file: no such mesh file nosuch.X"},
    {"DeeplyNested", "simulate", R"({"flock": {}, "x": )" + std::string(300, '[') + std::string(300, ']') + "}",
     "s.json: line 1: JSON nested deeper than 256 levels"},
    {"ClothResolutionOne", "simulate", cloth_with(R"({"nx": 1})"),
     "s.json: /cloth/nx: expected an integer in [2, 1024], got 1"},
    {"ClothResolutionHuge", "simulate", cloth_with(R"({"ny": 100000})"),
     "s.json: /cloth/ny: expected an integer in [2, 1024], got 100000"},
    {"NegativeClothMass", "optimize", cloth_with(R"({"mass": -0.1})"),
     "s.json: /cloth/mass: expected a number in [1e-09, 1e+06], got -0.1"},
    {"NegativeStretchStiffness", "simulate", cloth_with(R"({"stretch": -100})"),
     "s.json: /cloth/stretch: expected a number in [0, 1e+09], got -100"},
    {"OverflowingBendStiffness", "simulate", cloth_with(R"({"bend": -1e999})"),
     "s.json: not valid JSON: number overflow parsing '-1e999'"},
    {"ZeroClothWidth", "simulate", cloth_with(R"({"width": 0})"),
     "s.json: /cloth/width: expected a number in [0.0001, 10000], got 0"},
    {"ZeroAxis", "simulate", cloth_with(R"({"u_axis": [0, 0, 0]})"),
     "s.json: /cloth/u_axis: expected a non-zero direction"},
    {"SkewAxes", "simulate", cloth_with(R"({"u_axis": [1, 0, 0], "v_axis": [1, 1, 0]})"),
     "s.json: /cloth/v_axis: expected a direction perpendicular to \"u_axis\""},
    {"PinOutOfRange", "simulate", cloth_with(R"({"nx": 3, "ny": 3, "pins": [0, 9]})"),
     "s.json: /cloth/pins/1: expected an integer in [0, 8], got 9"},
    {"UnknownPinSet", "simulate", cloth_with(R"({"pins": "everywhere"})"),
     "s.json: /cloth/pins: expected one of \"none\", \"top_edge\", \"bottom_edge\", \"left_edge\", "
     "\"right_edge\", \"top_corners\", \"bottom_corners\", \"corners\", got \"everywhere\""},
    {"SpindleTorus", "simulate",
     cloth_with(R"({"colliders": [{"type": "torus", "radius": 0.5, "tube_radius": 0.6}]})"),
     "s.json: /cloth/colliders/0/tube_radius: expected less than \"radius\" (a ring, not a spindle torus)"},
    {"NaNGravityComponent", "simulate", cloth_with(R"({"gravity": [0, "nan", 0]})"),
     "s.json: /cloth/gravity/1: expected a finite number in [-10000.000000, 10000.000000], got \"nan\""},
    // Unknown keys, at every level.
    {"UnknownTopLevelKey", "simulate", flock_with("{}", R"(, "colour": "red")"),
     "s.json: /colour: unknown key (check its spelling; see README 'Scene files')"},
    {"MisspelledFlockKey", "simulate", flock_with(R"({"agnets": 10})"),
     "s.json: /flock/agnets: unknown key (check its spelling; see README 'Scene files')"},
    {"UnknownColliderKey", "simulate", cloth_with(R"({"colliders": [{"type": "ground", "fricton": 1}]})"),
     "s.json: /cloth/colliders/0/fricton: unknown key (check its spelling; see README 'Scene files')"},
    // Keyframes.
    {"KeyframeAfterEnd", "optimize",
     flock_with("{}", R"(, "objectives": [{"type": "center_of_mass", "frame": 11, "target": [0, 0, 0]}])"),
     "s.json: /objectives/0/frame: expected an integer in [0, 10], got 11"},
    {"KeyframeBeforeStart", "optimize",
     flock_with("{}", R"(, "objectives": [{"type": "center_of_mass", "frame": -1, "target": [0, 0, 0]}])"),
     "s.json: /objectives/0/frame: expected an integer in [0, 10], got -1"},
    {"KeyframeWithoutFrame", "optimize",
     flock_with("{}", R"(, "objectives": [{"type": "center_of_mass", "target": [0, 0, 0]}])"),
     "s.json: /objectives/0/frame: required key is missing"},
    {"ShapeKeyframeOnCloth", "optimize",
     cloth_with("{}", R"(, "objectives": [{"type": "shape", "frame": 5, "polygon": [[0,0],[1,0],[0,1]]}])"),
     "s.json: /objectives/0/type: \"shape\" keyframes are for flocks; use \"position\" or \"arch\" for cloth"},
    {"PolygonTooShort", "optimize",
     flock_with("{}", R"(, "objectives": [{"type": "shape", "frame": 5, "polygon": [[0,0],[1,0]]}])"),
     "s.json: /objectives/0/polygon: expected a list of at least 3 [a, b] points, got array [[0,0],[1,0]]"},
    {"TargetCountMismatch", "optimize",
     flock_with(R"({"agents": 4})",
                R"(, "objectives": [{"type": "position", "frame": 5, "targets": [[0,0,0],[1,0,0]]}])"),
     "s.json: /objectives/0/targets: expected 1 target or one per particle (4), got 2"},
    {"ObjectivesNotAList", "optimize", flock_with("{}", R"(, "objectives": {"type": "shape"})"),
     "s.json: /objectives: expected an array of at least 0 objects, got object {\"type\":\"shape\"}"},
    {"UnknownControlKind", "optimize", flock_with("{}", R"(, "controls": {"kind": "magic"})"),
     "s.json: /controls/kind: expected one of \"per_step\", \"per_frame\", \"initial_velocity\", \"initial_rigid_velocity\", \"initial_lattice_velocity\", got \"magic\""},
    {"NegativeControlWeight", "optimize", flock_with("{}", R"(, "controls": {"alpha": -1})"),
     "s.json: /controls/alpha: expected a number in [0, 1e+06], got -1"},
    {"RenderWidthZero", "simulate", flock_with("{}", R"(, "render": {"width": 0})"),
     "s.json: /render/width: expected an integer in [16, 8192], got 0"},
};

void PrintTo(const BadScene& c, std::ostream* os) { *os << c.name; }

class BadSceneCli : public TempDirTest, public ::testing::WithParamInterface<BadScene> {};

TEST_P(BadSceneCli, GivesItsOneLineMessageAndWritesNothing) {
  const BadScene& c = GetParam();
  write("s.json", c.scene);
  const auto before = list_tree(dir_);
  const CliResult r = run_keyframe(std::string(c.command) + " s.json", dir_);
  EXPECT_EQ(r.code, kExitInput) << r.output;
  EXPECT_EQ(r.output, "keyframe: error: " + c.message + "\n");
  EXPECT_EQ(list_tree(dir_), before) << c.command << " wrote something for a bad scene";
}

INSTANTIATE_TEST_SUITE_P(Reliability, BadSceneCli, ::testing::ValuesIn(kBadScenes),
                         [](const auto& info) { return std::string(info.param.name); });

class OtherBadInputCli : public TempDirTest {};

class BadRunDirCli : public TempDirTest {
 protected:
  // A real run directory made by `simulate` of a small flock.
  fs::path make_run() {
    write("f.json", small_flock_scene(4));
    const CliResult r = run_keyframe("simulate f.json --out run", dir_);
    EXPECT_EQ(r.code, 0) << r.output;
    return dir_ / "run";
  }
  void expect_render_fails(const std::string& args, int code, const std::string& message) {
    const auto before = list_tree(dir_);
    const CliResult r = run_keyframe("render " + args, dir_);
    EXPECT_EQ(r.code, code) << r.output;
    EXPECT_EQ(r.output, "keyframe: error: " + message + "\n");
    EXPECT_EQ(list_tree(dir_), before) << "render wrote something for a bad request";
  }
};

TEST_F(BadRunDirCli, MissingRunDirectory) {
  expect_render_fails("nowhere", kExitInput, "nowhere: not a run directory (does not exist)");
}

TEST_F(BadRunDirCli, RunDirectoryWithoutScene) {
  fs::create_directories(dir_ / "empty");
  expect_render_fails("empty", kExitInput, "empty: not a run directory (no scene.json)");
}

TEST_F(BadRunDirCli, MissingTrajectory) {
  const fs::path run = make_run();
  fs::remove(run / "trajectory.bin");
  expect_render_fails("run", kExitInput,
                      "run: no trajectory.bin to render (run 'keyframe simulate' or 'keyframe run' first)");
}

TEST_F(BadRunDirCli, TruncatedTrajectory) {
  const fs::path run = make_run();
  const auto size = fs::file_size(run / "trajectory.bin");
  fs::resize_file(run / "trajectory.bin", size - 8);
  expect_render_fails("run", kExitInput,
                      "run/trajectory.bin: truncated or padded (expected " + std::to_string(size) + " bytes)");
}

TEST_F(BadRunDirCli, TrajectoryTruncatedInsideHeader) {
  const fs::path run = make_run();
  fs::resize_file(run / "trajectory.bin", 10);
  expect_render_fails("run", kExitInput, "run/trajectory.bin: not a keyframe trajectory (bad header)");
}

TEST_F(BadRunDirCli, TrajectoryInAnotherFormat) {
  const fs::path run = make_run();
  write_text(run / "trajectory.bin", "\x89PNG\r\n\x1a\n this is an image, not a trajectory");
  expect_render_fails("run", kExitInput, "run/trajectory.bin: not a keyframe trajectory (bad header)");
}

TEST_F(BadRunDirCli, TrajectoryOfAnotherScene) {
  // A trajectory of 12 agents next to a scene of 3: the header is fine, the particle count is not.
  const fs::path run = make_run();
  write("g.json", R"({"time": {"frames": 4}, "flock": {"agents": 3}})");
  ASSERT_EQ(run_keyframe("simulate g.json --out other", dir_).code, 0);
  fs::copy_file(dir_ / "other" / "scene.json", run / "scene.json", fs::copy_options::overwrite_existing);
  const CliResult r = run_keyframe("render run", dir_);
  EXPECT_EQ(r.code, kExitInput) << r.output;
  EXPECT_FALSE(fs::exists(run / "frames")) << r.output;
}

TEST_F(BadRunDirCli, CorruptSceneCopy) {
  const fs::path run = make_run();
  write_text(run / "scene.json", "{\"flock\": ");
  expect_render_fails("run", kExitInput,
                      "run/scene.json: not valid JSON: parse error at line 1, column 11: syntax error while "
                      "parsing value - unexpected end of input; expected '[', '{', or a literal");
}

TEST_F(BadRunDirCli, BadSizeOption) {
  const fs::path run = make_run();
  expect_render_fails("run --size 64by48", kExitInput, "--size: expected WxH such as 1280x720, got \"64by48\"");
}

TEST_F(BadRunDirCli, FramesPastTheEnd) {
  const fs::path run = make_run();
  const CliResult r = run_keyframe("render run --frames 7:9", dir_);
  EXPECT_EQ(r.code, kExitInput) << r.output;
  EXPECT_FALSE(fs::exists(run / "frames"));
}

class UnwritableOutputCli : public TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    write("f.json", small_flock_scene(4));
  }
  void TearDown() override {
    if (mounted_) ::umount2(mount_.c_str(), MNT_DETACH);
    TempDirTest::TearDown();
  }
  // Mounts a tmpfs of `options` at dir_/name; false (with the reason in `why_`) if not permitted.
  bool mount_tmpfs(const std::string& name, const std::string& options) {
    mount_ = dir_ / name;
    fs::create_directories(mount_);
    if (::mount("tmpfs", mount_.c_str(), "tmpfs", options.find("ro") == 0 ? MS_RDONLY : 0,
                options.c_str()) != 0) {
      why_ = std::strerror(errno);
      return false;
    }
    mounted_ = true;
    return true;
  }
  fs::path mount_;
  bool mounted_ = false;
  std::string why_;
};

TEST_F(UnwritableOutputCli, FileWhereTheRunDirectoryShouldBe) {
  write("taken", "a file, not a directory");
  const CliResult r = run_keyframe("simulate f.json --out taken/run", dir_);
  EXPECT_EQ(r.code, kExitOutput) << r.output;
  EXPECT_EQ(r.output.rfind("keyframe: error: taken/run: cannot create directory: ", 0), 0u) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  EXPECT_EQ(read_text(dir_ / "taken"), "a file, not a directory");
}

TEST_F(UnwritableOutputCli, RunDirectoryIsAFile) {
  write("taken", "a file, not a directory");
  const CliResult r = run_keyframe("optimize f.json --quiet --out taken", dir_);
  EXPECT_EQ(r.code, kExitOutput) << r.output;
  EXPECT_EQ(r.output.rfind("keyframe: error: taken: cannot create directory: ", 0), 0u) << r.output;
  EXPECT_EQ(read_text(dir_ / "taken"), "a file, not a directory");
}

TEST_F(UnwritableOutputCli, ReadOnlyDirectory) {
  // Root ignores permission bits, so a read-only mount is the honest test; chmod is the fallback.
  fs::path ro;
  if (mount_tmpfs("ro", "ro,size=64k")) {
    ro = mount_;
  } else if (::geteuid() != 0) {
    ro = dir_ / "ro";
    fs::permissions(ro, fs::perms::owner_read | fs::perms::owner_exec);
  } else {
    GTEST_SKIP() << "running as root without permission to mount a read-only tmpfs (" << why_ << ")";
  }
  const CliResult r = run_keyframe("simulate f.json --out ro/run", dir_);
  EXPECT_EQ(r.code, kExitOutput) << r.output;
  EXPECT_EQ(r.output.rfind("keyframe: error: ro/run: cannot create directory: ", 0), 0u) << r.output;
  EXPECT_TRUE(list_tree(ro).empty());
}

TEST_F(UnwritableOutputCli, DiskFullLeavesNoPartialFiles) {
  if (!mount_tmpfs("small", "size=64k"))
    GTEST_SKIP() << "cannot mount a 64 KiB tmpfs to fill up (" << why_ << "); needs root";
  // 200 agents x 41 frames x 48 bytes is ~390 KiB of trajectory: cannot fit.
  write("big.json", R"({"time": {"frames": 40}, "flock": {"agents": 200, "spawn": {"radius": 10}}})");
  const CliResult r = run_keyframe("simulate big.json --out small/run", dir_);
  EXPECT_EQ(r.code, kExitOutput) << r.output;
  EXPECT_EQ(r.output, "keyframe: error: small/run/trajectory.bin: write failed (disk full or not writable)\n");
  for (const auto& f : list_tree(mount_)) {
    EXPECT_NE(f, "run/trajectory.bin");
    EXPECT_EQ(f.find(".tmp"), std::string::npos) << "temp file left behind: " << f;
  }
}

TEST_F(UnwritableOutputCli, DiskFullDuringOptimize) {
  if (!mount_tmpfs("small", "size=64k"))
    GTEST_SKIP() << "cannot mount a 64 KiB tmpfs to fill up (" << why_ << "); needs root";
  write("big.json", R"({"time": {"frames": 40}, "flock": {"agents": 200, "spawn": {"radius": 10}},
    "objectives": [{"type": "center_of_mass", "frame": 40, "target": [0, 0, 3]}],
    "controls": {"kind": "initial_velocity"}, "optimizer": {"max_evaluations": 2}})");
  const CliResult r = run_keyframe("optimize big.json --quiet --out small/run", dir_);
  EXPECT_EQ(r.code, kExitOutput) << r.output;
  EXPECT_NE(r.output.find("keyframe: error: small/run/"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(": write failed (disk full or not writable)\n"), std::string::npos) << r.output;
  for (const auto& f : list_tree(mount_)) EXPECT_EQ(f.find(".tmp"), std::string::npos) << "temp file left: " << f;
}

TEST_F(UnwritableOutputCli, DevFullAsRunDirectory) {
  const CliResult r = run_keyframe("simulate f.json --out /dev/full", dir_);
  EXPECT_EQ(r.code, kExitOutput) << r.output;
  EXPECT_EQ(r.output.rfind("keyframe: error: /dev/full: cannot create directory", 0), 0u) << r.output;
}

TEST_F(OtherBadInputCli, BadThreadCountIsAUsageError) {
  write("f.json", small_flock_scene(4));
  const CliResult r = run_keyframe("--threads -3 simulate f.json", dir_);
  EXPECT_EQ(r.code, kExitUsage) << r.output;
  EXPECT_FALSE(fs::exists(dir_ / "out"));
}

TEST_F(OtherBadInputCli, SceneThatIsADirectory) {
  fs::create_directories(dir_ / "d.json");
  const CliResult r = run_keyframe("simulate d.json", dir_);
  EXPECT_EQ(r.code, kExitInput) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  EXPECT_EQ(r.output.rfind("keyframe: error: d.json: ", 0), 0u) << r.output;
  EXPECT_FALSE(fs::exists(dir_ / "out"));
}

}  // namespace
}  // namespace kf::reliability
