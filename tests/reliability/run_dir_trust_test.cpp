// Run directories through the real `keyframe` binary: names read from them stay inside them, corrupt
// files are refused with exit 3, a failed command leaves an existing run as it was, a run or render
// replaces its frames whole (no stale frame survives), two writers are refused, and a full disk during
// export gives exit 4 with no partial file.
#include <fcntl.h>
#include <sys/file.h>
#include <sys/mount.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <map>

#include "app/optimize_job.h"
#include "cli_harness.h"
#include "core/error.h"
#include "core/trajectory.h"
#include "opt/controls_file.h"

namespace kf::reliability {
namespace {

// A run that was written: its keyframes reached (0) or not within the budget (kExitNotReached).
bool wrote_run(int code) { return code == 0 || code == kExitNotReached; }

// Every regular file under `dir` with its bytes (hidden temporaries included), to compare before/after.
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& rel : list_tree(dir))
    if (rel.back() != '/') files[rel] = read_text(dir / rel);
  return files;
}

class RunDirTrust : public TempDirTest {
 protected:
  // A run directory made by `simulate` of a small flock of `frames` frames.
  fs::path simulate_run(const std::string& name = "run", int frames = 4) {
    write("f.json", small_flock_scene(frames));
    const CliResult r = run_keyframe("simulate f.json --out " + name, dir_);
    EXPECT_EQ(r.code, 0) << r.output;
    return dir_ / name;
  }
  // Runs `args`, expects `code` and exactly "keyframe: error: MESSAGE\n", and that nothing changed on disk.
  void expect_refused_unchanged(const std::string& args, int code, const std::string& message) {
    const auto before = snapshot(dir_);
    const CliResult r = run_keyframe(args, dir_);
    EXPECT_EQ(r.code, code) << r.output;
    EXPECT_EQ(r.output, "keyframe: error: " + message + "\n");
    EXPECT_EQ(snapshot(dir_), before) << args << " changed files";
  }
};

// --- Names read from a run directory cannot leave it ---

TEST_F(RunDirTrust, SceneNameWithParentStepsIsRefusedByExport) {
  simulate_run();
  write_text(dir_ / "run/scene_name.txt", "../../../NAME\n/tmp\n");
  expect_refused_unchanged("export run", kExitInput,
                           "run/scene_name.txt: line 1: the scene's name contains '/', got \"../../../NAME\" (it "
                           "names files inside the run directory)");
  write_text(dir_ / "run/scene_name.txt", "..\n/tmp\n");
  expect_refused_unchanged("export run", kExitInput,
                           "run/scene_name.txt: line 1: the scene's name is \"..\", got \"..\" (it names files "
                           "inside the run directory)");
}

TEST_F(RunDirTrust, SceneNameWithParentStepsIsRefusedByFigure) {
  simulate_run();
  write_text(dir_ / "run/scene_name.txt", "../../escape\n");
  fs::create_directories(dir_ / "sheets/x");
  expect_refused_unchanged("figure run --out-dir sheets/x --frames 0,4", kExitInput,
                           "run/scene_name.txt: line 1: the scene's name contains '/', got \"../../escape\" (it "
                           "names files inside the run directory)");
}

TEST_F(RunDirTrust, SceneNameWithNewlineOrExtraLinesIsRefused) {
  simulate_run();
  write_text(dir_ / "run/scene_name.txt", "a\nb\nc\n");
  expect_refused_unchanged("render run", kExitInput,
                           "run/scene_name.txt: more than two lines (expected the scene's name and its directory)");
  write_text(dir_ / "run/scene_name.txt", "na\tme\n/tmp\n");
  expect_refused_unchanged("optimize --resume run --quiet", kExitInput,
                           "run/scene_name.txt: line 1: the scene's name contains a control character, got "
                           "\"na\\tme\" (it names files inside the run directory)");
}

TEST_F(RunDirTrust, SceneFileNamedDotsCannotNameItsRunDirectory) {
  write("...json", small_flock_scene(4));
  expect_refused_unchanged("simulate ...json", kExitInput,
                           "...json: the file's name is \"..\", so it cannot name the run directory (got \"..\"); "
                           "rename the file or pass --out");
  EXPECT_FALSE(fs::exists(dir_ / "out"));
  expect_refused_unchanged("optimize ...json --quiet", kExitInput,
                           "...json: the file's name is \"..\", so it cannot name the run directory (got \"..\"); "
                           "rename the file or pass --out");
  // With --out it is an ordinary scene.
  const CliResult r = run_keyframe("simulate ...json --out dots", dir_);
  EXPECT_EQ(r.code, 0) << r.output;
}

TEST_F(RunDirTrust, OutWithANewlineIsRefused) {
  write("f.json", small_flock_scene(4));
  expect_refused_unchanged("simulate f.json --out \"$(printf 'nl\\ntouch PWNED\\n#')\"", kExitInput,
                           "--out: contains a control character, got \"nl\\ntouch PWNED\\n#\"");
}

// --- Corrupt run-directory files: exit 3 naming the file, nothing written ---

TEST_F(RunDirTrust, TrajectoryHoldingNaNIsRefusedByRenderExportAndFigure) {
  const fs::path run = simulate_run();
  Trajectory t = load_trajectory(run / "trajectory.bin");
  t.x[2][4] = std::numeric_limits<double>::quiet_NaN();
  save_trajectory(run / "trajectory.bin", t);
  const std::string message = "run/trajectory.bin: frame 2 holds a non-finite position (NaN or infinity)";
  expect_refused_unchanged("render run", kExitInput, message);
  expect_refused_unchanged("export run", kExitInput, message);
  expect_refused_unchanged("export run --format obj", kExitInput, message);
  expect_refused_unchanged("figure run --out-dir . --frames 0,4", kExitInput, message);
  t.x[2][4] = 0;
  t.v[3][0] = std::numeric_limits<double>::infinity();
  save_trajectory(run / "trajectory.bin", t);
  expect_refused_unchanged("export run --format pc2", kExitInput,
                           "run/trajectory.bin: frame 3 holds a non-finite velocity (NaN or infinity)");
}

TEST_F(RunDirTrust, TrajectoryWithFewerFramesThanTheSceneIsRefused) {
  const fs::path run = simulate_run();
  Trajectory t = load_trajectory(run / "trajectory.bin");
  t.x.resize(3);
  t.v.resize(3);
  save_trajectory(run / "trajectory.bin", t);
  const std::string message =
      "run/trajectory.bin: holds 3 frames but scene.json describes 5 (frames 0..4)";
  expect_refused_unchanged("render run", kExitInput, message);
  expect_refused_unchanged("export run", kExitInput, message);
  expect_refused_unchanged("figure run --out-dir . --frames 0,2", kExitInput, message);
}

TEST_F(RunDirTrust, DeeplyNestedSceneIsRefusedWithoutCrashing) {
  std::string deep = R"({"flock": {}, "x": )" + std::string(100000, '[') + std::string(100000, ']') + "}";
  write("deep.json", deep);
  expect_refused_unchanged("simulate deep.json", kExitInput, "deep.json: line 1: JSON nested deeper than 256 levels");
  // A run directory's scene copy is read the same way.
  simulate_run();
  write_text(dir_ / "run/scene.json", deep);
  expect_refused_unchanged("render run", kExitInput, "run/scene.json: line 1: JSON nested deeper than 256 levels");
}

// --- A failed command leaves an existing run as it was ---

TEST_F(RunDirTrust, FailedOptimizeLeavesTheExistingRunUnchanged) {
  write("f.json", small_flock_scene(6));
  ASSERT_TRUE(wrote_run(run_keyframe("optimize f.json --quiet --out run", dir_).code));
  // A coverage spacing that gives 10^8 samples, refused with the scene (an older reader refused it only
  // once the objective was built, after it had replaced scene.json).
  write("bad.json", R"({"time": {"frames": 6}, "flock": {"agents": 12, "spawn": {"radius": 3}},
    "objectives": [{"type": "shape", "frame": 6, "polygon": [[-5, -5], [5, -5], [5, 5], [-5, 5]],
                    "coverage": {"weight": 1, "spacing": 0.001}}],
    "optimizer": {"max_evaluations": 2}})");
  expect_refused_unchanged("optimize bad.json --quiet --out run", kExitInput,
                           "bad.json: /objectives/0/coverage/spacing: the coverage grid over the shape's "
                           "bounding box would have 1e+08 samples (at most 100,000): raise \"spacing\"");
  // The run still renders and resumes as itself.
  EXPECT_EQ(run_keyframe("render run", dir_).code, 0);
  EXPECT_TRUE(fs::exists(dir_ / "run/frames/frame_0006.png"));
}

TEST_F(RunDirTrust, ResumeIntoABrokenRunChangesNothingOnFailure) {
  write("f.json", small_flock_scene(6));
  ASSERT_TRUE(wrote_run(run_keyframe("optimize f.json --quiet --out run", dir_).code));
  // A truncated record of the evaluations: refused before the job starts; the run's files stay as they were.
  fs::resize_file(dir_ / "run/evaluations.bin", fs::file_size(dir_ / "run/evaluations.bin") - 5);
  const auto before = snapshot(dir_ / "run");
  CliResult r = run_keyframe("optimize --resume run --quiet", dir_);
  EXPECT_EQ(r.code, kExitInput) << r.output;
  EXPECT_EQ(r.output.rfind("keyframe: error: run/evaluations.bin: truncated", 0), 0u) << r.output;
  EXPECT_EQ(snapshot(dir_ / "run"), before);
  // Without it, controls.bin of another scene: refused once the job has started, the run still unchanged.
  fs::remove(dir_ / "run/evaluations.bin");
  write("g.json", R"({"time": {"frames": 6}, "flock": {"agents": 3},
    "objectives": [{"type": "center_of_mass", "frame": 6, "target": [1, 0, 2]}],
    "controls": {"kind": "per_frame"}, "optimizer": {"max_evaluations": 2}})");
  ASSERT_TRUE(wrote_run(run_keyframe("optimize g.json --quiet --out other", dir_).code));
  fs::copy_file(dir_ / "other/controls.bin", dir_ / "run/controls.bin", fs::copy_options::overwrite_existing);
  const auto before2 = snapshot(dir_ / "run");
  r = run_keyframe("optimize --resume run --quiet", dir_);
  EXPECT_EQ(r.code, kExitInput) << r.output;
  EXPECT_NE(r.output.find("run/controls.bin: holds "), std::string::npos) << r.output;
  EXPECT_EQ(snapshot(dir_ / "run"), before2);
  for (const auto& f : list_tree(dir_)) EXPECT_EQ(f.find(".new-"), std::string::npos) << "staging left: " << f;
}

TEST_F(RunDirTrust, ResumeFromControlsWithNoFiniteObjectiveIsRefused) {
  write("f.json", small_flock_scene(6));
  ASSERT_TRUE(wrote_run(run_keyframe("optimize f.json --quiet --out run", dir_).code));
  // A run without its record of evaluations resumes from controls.bin; controls of 1e300 give an infinite
  // objective (their effort alone overflows). Refused up front as bad input (not "not reached", not a silent restart), run unchanged.
  fs::remove(dir_ / "run/evaluations.bin");
  int substeps = 0;
  const VecX z = load_controls(dir_ / "run/controls.bin", &substeps);
  save_controls(dir_ / "run/controls.bin", VecX::Constant(z.size(), 1e300), substeps);
  expect_refused_unchanged("optimize --resume run --quiet", kExitInput,
                           "run/controls.bin: the objective is not finite under these controls (largest magnitude "
                           "1e+300), so there is no run to resume from them");
  for (const auto& f : list_tree(dir_)) EXPECT_EQ(f.find(".new-"), std::string::npos) << "staging left: " << f;
  // The same run with its own controls back resumes.
  save_controls(dir_ / "run/controls.bin", z, substeps);
  EXPECT_TRUE(wrote_run(run_keyframe("optimize --resume run --quiet", dir_).code));
}

TEST_F(RunDirTrust, ResumeWhereTrajectoryIsADirectoryReplacesTheRunWhole) {
  write("f.json", small_flock_scene(6));
  ASSERT_TRUE(wrote_run(run_keyframe("optimize f.json --quiet --out run --max-evaluations 2", dir_).code));
  fs::remove(dir_ / "run/trajectory.bin");
  fs::create_directories(dir_ / "run/trajectory.bin");
  const CliResult r = run_keyframe("optimize --resume run --quiet --max-evaluations 2", dir_);
  // The new run is written beside the old one and swapped in whole: a complete run, no odd directory.
  EXPECT_TRUE(wrote_run(r.code)) << r.output;
  EXPECT_TRUE(fs::is_regular_file(dir_ / "run/trajectory.bin"));
  EXPECT_NO_THROW(load_trajectory(dir_ / "run/trajectory.bin"));
  EXPECT_TRUE(fs::is_regular_file(dir_ / "run/controls.bin"));
}

// --- No stale frames ---

TEST_F(RunDirTrust, RenderingAShorterRunLeavesNoOldFrames) {
  simulate_run("run", 8);
  ASSERT_EQ(run_keyframe("render run", dir_).code, 0);
  ASSERT_TRUE(fs::exists(dir_ / "run/frames/frame_0008.png"));
  ASSERT_EQ(run_keyframe("render run --turntable 2", dir_).code, 0);
  simulate_run("run", 4);
  // The new run replaced the directory whole: its frames went with it.
  EXPECT_FALSE(fs::exists(dir_ / "run/frames"));
  ASSERT_EQ(run_keyframe("render run", dir_).code, 0);
  std::vector<std::string> frames;
  for (const auto& f : list_tree(dir_ / "run/frames")) frames.push_back(f);
  EXPECT_EQ(frames, (std::vector<std::string>{"frame_0000.png", "frame_0001.png", "frame_0002.png",
                                              "frame_0003.png", "frame_0004.png"}));
}

TEST_F(RunDirTrust, RerenderingReplacesFramesWholeAndPartsDropFramesPastTheEnd) {
  const fs::path run = simulate_run("run", 4);
  ASSERT_EQ(run_keyframe("render run", dir_).code, 0);
  // Frames an earlier, longer render left (copied in by hand here) go when the run is rendered again...
  fs::copy_file(run / "frames/frame_0004.png", run / "frames/frame_0009.png");
  ASSERT_EQ(run_keyframe("render run", dir_).code, 0);
  EXPECT_FALSE(fs::exists(run / "frames/frame_0009.png"));
  // ...and when only a part is rendered (a farm task), frames past the trajectory's end go too.
  fs::copy_file(run / "frames/frame_0004.png", run / "frames/frame_0007.png");
  ASSERT_EQ(run_keyframe("render run --frames 1:3", dir_).code, 0);
  EXPECT_FALSE(fs::exists(run / "frames/frame_0007.png"));
  EXPECT_TRUE(fs::exists(run / "frames/frame_0004.png"));
  for (const auto& f : list_tree(run)) EXPECT_EQ(f.find(".new-"), std::string::npos) << "staging left: " << f;
}

TEST_F(RunDirTrust, RunIntoADirectoryOfALongerRunLeavesNoOldFrames) {
  write("long.json", small_flock_scene(8));
  ASSERT_TRUE(wrote_run(run_keyframe("run long.json --quiet --out run --max-evaluations 1", dir_).code));
  ASSERT_TRUE(fs::exists(dir_ / "run/frames/frame_0008.png"));
  write("short.json", small_flock_scene(4));
  const CliResult r = run_keyframe("run short.json --quiet --out run --max-evaluations 1", dir_);
  ASSERT_TRUE(wrote_run(r.code)) << r.output;
  EXPECT_TRUE(fs::exists(dir_ / "run/frames/frame_0004.png"));
  EXPECT_FALSE(fs::exists(dir_ / "run/frames/frame_0005.png"));
}

// --- Locking ---

TEST_F(RunDirTrust, SecondWriterOfALockedRunIsRefused) {
  const fs::path run = simulate_run();
  // Hold the lock as a running optimisation would.
  const int fd = ::open(run.c_str(), O_RDONLY | O_DIRECTORY);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);
  const std::string busy =
      "run: in use by another keyframe command (it is being written or rendered); wait for it to finish or "
      "choose another directory";
  expect_refused_unchanged("simulate f.json --out run", kExitOutput, busy);
  expect_refused_unchanged("optimize f.json --quiet --out run", kExitOutput, busy);
  expect_refused_unchanged("render run", kExitOutput, busy);
  expect_refused_unchanged("export run", kExitOutput,
                           "run: in use by another keyframe command (it is being rewritten); wait for it to finish "
                           "or choose another directory");
  ::close(fd);
  EXPECT_EQ(run_keyframe("render run", dir_).code, 0);
}

// --- Export on a full disk ---

class ExportDiskFull : public RunDirTrust {
 protected:
  void TearDown() override {
    if (mounted_) ::umount2((dir_ / "small").c_str(), MNT_DETACH);
    RunDirTrust::TearDown();
  }
  bool mounted_ = false;
};

TEST_F(ExportDiskFull, ObjAndPlyGiveExit4AndNoPartialFile) {
  fs::create_directories(dir_ / "small");
  if (::mount("tmpfs", (dir_ / "small").c_str(), "tmpfs", 0, "size=96k") != 0)
    GTEST_SKIP() << "cannot mount a small tmpfs to fill up (" << std::strerror(errno) << "); needs root";
  mounted_ = true;
  write("f.json", small_flock_scene(20));
  ASSERT_EQ(run_keyframe("simulate f.json --out small/run", dir_).code, 0);
  // Fill the disk, then free 8 KiB: room for the export's first bytes, not for its files.
  {
    std::ofstream filler(dir_ / "small/filler", std::ios::binary);
    const std::string block(4096, 'x');
    while (filler.write(block.data(), std::streamsize(block.size()))) {}
  }
  fs::resize_file(dir_ / "small/filler", fs::file_size(dir_ / "small/filler") - 8192);
  for (const std::string format : {"obj", "ply"}) {
    const CliResult r = run_keyframe("export small/run --format " + format, dir_);
    EXPECT_EQ(r.code, kExitOutput) << r.output;
    EXPECT_EQ(r.output.rfind("keyframe: error: small/run/export/frame_", 0), 0u) << r.output;
    EXPECT_NE(r.output.find(": write failed (disk full or not writable)\n"), std::string::npos) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    for (const auto& f : list_tree(dir_ / "small/run")) {
      EXPECT_EQ(f.find(".partial"), std::string::npos) << "partial export left: " << f;
      EXPECT_EQ(f.find("." + format), std::string::npos) << "exported file left: " << f;
    }
  }
}

}  // namespace
}  // namespace kf::reliability
