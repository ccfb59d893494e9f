// A run directory replays exactly: `optimize` stores the step schedule its result was judged under (schedule.bin,
// the cloth's split pattern), and what simulates controls.bin again holds it: a resume continues from the
// objective the run ended at and rewrites trajectory.bin bit for bit, `gradcheck --at` checks at the run's own
// objective. A run directory without the file still loads, and says once that the schedule is chosen anew; a
// broken one is refused in one line naming it, and nothing is written.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <cstring>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "../reliability/cli_harness.h"
#include "core/error.h"
#include "opt/controls_file.h"
#include "opt/schedule_file.h"
#include "scene/scene.h"
#include "sim/cloth/cloth_split_pattern.h"

namespace kf {
namespace {
namespace fs = std::filesystem;
using reliability::read_text;
using reliability::run_keyframe;

// A curtain pinned along its top edge, released flat at one step per frame and asked to swing its free edge
// aside: the energy check splits its steps, so the strategy holds a split pattern.
const char* kCurtain = R"({
  "time": {"fps": 30, "frames": 12},
  "cloth": {"nx": 8, "ny": 6, "width": 0.8, "height": 0.5, "mass": 0.2,
            "origin": [-0.4, 1.5, 0.5], "u_axis": [1, 0, 0], "v_axis": [0, 0, -1], "pins": "top_edge"},
  "objectives": [{"type": "center_of_mass", "frame": 12, "particles": [0, 1, 2, 3, 4, 5, 6, 7],
                  "target": [0.1, 1.1, 0.2]}],
  "controls": {"kind": "per_frame", "alpha": 1e-4},
  "optimizer": {"max_evaluations": 40}
})";

nlohmann::json report(const fs::path& run) { return nlohmann::json::parse(read_text(run / "report.json")); }

std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) files[fs::relative(e.path(), dir).string()] = read_text(e.path());
  return files;
}

size_t count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

bool wrote_run(int code) { return code == 0 || code == kExitNotReached; }

class ScheduleReplayCli : public reliability::TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    write("curtain.json", kCurtain);
    const reliability::CliResult r = run_keyframe("optimize curtain.json --quiet --out run", dir_);
    ASSERT_TRUE(wrote_run(r.code)) << r.output;
    run_report = report(dir_ / "run");
  }
  // A copy of the run as an older or a trimmed run directory: without evaluations.bin (a resume then continues
  // from controls.bin), and without schedule.bin when `with_schedule` is false.
  fs::path copy_run(const std::string& name, bool with_schedule) {
    fs::copy(dir_ / "run", dir_ / name, fs::copy_options::recursive);
    fs::remove(dir_ / name / "evaluations.bin");
    if (!with_schedule) fs::remove(dir_ / name / "schedule.bin");
    return dir_ / name;
  }
  void write(const std::string& name, const std::string& text) { reliability::write_text(dir_ / name, text); }
  nlohmann::json run_report;
};

TEST_F(ScheduleReplayCli, TheRunStoresTheSplitPatternItsResultWasJudgedUnder) {
  const Scene scene = load_scene(dir_ / "run/scene.json");
  int substeps = 0;
  const VecX z = load_controls(dir_ / "run/controls.bin", &substeps);
  const StepSchedule s = load_schedule(dir_ / "run/schedule.bin", scene, z, substeps);
  ASSERT_NE(cloth_split_steps(s), nullptr);
  int split = 0;
  for (const auto& pattern : *cloth_split_steps(s)) split += pattern.size() > 1;
  EXPECT_GT(split, 0) << "the curtain's steps should be split";
  EXPECT_EQ(int(cloth_split_steps(s)->size()), scene.time.steps());
}

TEST_F(ScheduleReplayCli, ResumedFromControlsItReplaysTheTrajectoryBitForBit) {
  // One evaluation: the resumed stage simulates the run's controls and keeps them.
  const fs::path with = copy_run("with", true), without = copy_run("without", false);
  const reliability::CliResult a = run_keyframe("optimize --resume with --quiet --max-evaluations 1", dir_);
  ASSERT_TRUE(wrote_run(a.code)) << a.output;
  EXPECT_EQ(a.output.find("warning"), std::string::npos) << a.output;
  EXPECT_TRUE(read_text(with / "trajectory.bin") == read_text(dir_ / "run/trajectory.bin")) << "trajectory differs";
  EXPECT_EQ(report(with).at("final_objective").get<double>(), run_report.at("final_objective").get<double>());
  EXPECT_TRUE(read_text(with / "schedule.bin") == read_text(dir_ / "run/schedule.bin"));

  // Without the schedule (a run directory from before it was stored): loads, says so once, and lands elsewhere.
  const reliability::CliResult b = run_keyframe("optimize --resume without --quiet --max-evaluations 1", dir_);
  ASSERT_TRUE(wrote_run(b.code)) << b.output;
  EXPECT_EQ(count(b.output, "keyframe: warning: without/schedule.bin: none stored"), 1u) << b.output;
  EXPECT_FALSE(read_text(without / "trajectory.bin") == read_text(dir_ / "run/trajectory.bin"))
      << "chosen anew, the schedule was the run's: this scene no longer tells the two apart";
}

TEST_F(ScheduleReplayCli, ResumedFromControlsItStartsAtTheRunsFinalObjective) {
  copy_run("with", true);
  copy_run("without", false);
  const double final_phi = run_report.at("final_objective").get<double>();
  ASSERT_TRUE(wrote_run(run_keyframe("optimize --resume with --quiet", dir_).code));
  EXPECT_EQ(report(dir_ / "with").at("initial_objective").get<double>(), final_phi);
  EXPECT_LE(report(dir_ / "with").at("final_objective").get<double>(), final_phi);
  ASSERT_TRUE(wrote_run(run_keyframe("optimize --resume without --quiet", dir_).code));
  EXPECT_NE(report(dir_ / "without").at("initial_objective").get<double>(), final_phi);
}

TEST_F(ScheduleReplayCli, GradcheckAtARunChecksAtTheRunsOwnObjective) {
  const auto phi_at = [&](const std::string& run, std::string* output) {
    const std::string cmd = "cd '" + dir_.string() + "' && '" KEYFRAME_BINARY "' gradcheck " + run +
                            "/scene.json --at " + run + " --samples 2 2>err.txt";
    FILE* p = popen(cmd.c_str(), "r");
    std::string out;
    char buf[4096];
    while (size_t n = fread(buf, 1, sizeof buf, p)) out.append(buf, n);
    EXPECT_EQ(pclose(p), 0) << out;
    *output = read_text(dir_ / "err.txt");
    return nlohmann::json::parse(out).at("phi").get<double>();
  };
  copy_run("without", false);
  std::string err;
  EXPECT_EQ(phi_at("run", &err), run_report.at("final_objective").get<double>());
  EXPECT_EQ(err.find("warning"), std::string::npos) << err;
  EXPECT_NE(phi_at("without", &err), run_report.at("final_objective").get<double>());
  EXPECT_EQ(count(err, "keyframe: warning: without/schedule.bin: none stored"), 1u) << err;
}

TEST_F(ScheduleReplayCli, ABrokenScheduleIsRefusedInOneLineAndNothingIsWritten) {
  const fs::path broken = copy_run("broken", true);
  const std::string good = read_text(broken / "schedule.bin");
  std::string huge = good;
  std::memset(&huge[16], 0xff, 4);  // 4294967295 steps claimed
  const struct {
    std::string bytes, line;
  } cases[] = {
      {good.substr(0, good.size() - 4), "broken/schedule.bin: truncated or oversized step schedule (12 steps and "},
      {huge, "broken/schedule.bin: truncated or oversized step schedule (4294967295 steps and "},
      {"KFCTRL01" + good.substr(8), "broken/schedule.bin: not a keyframe step schedule (bad magic)"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.line);
    reliability::write_text(broken / "schedule.bin", c.bytes);
    const auto before = snapshot(broken);
    for (const std::string& cmd : {std::string("optimize --resume broken --quiet"),
                                   std::string("gradcheck broken/scene.json --at broken --samples 2")}) {
      const reliability::CliResult r = run_keyframe(cmd, dir_);
      EXPECT_EQ(r.code, kExitInput) << cmd << "\n" << r.output;
      EXPECT_EQ(r.output.rfind("keyframe: error: " + c.line, 0), 0u) << cmd << "\n" << r.output;
      EXPECT_EQ(count(r.output, "\n"), 1u) << cmd << "\n" << r.output;
      EXPECT_EQ(snapshot(broken), before) << cmd;
    }
  }
  // A FIFO is refused without waiting for a writer.
  fs::remove(broken / "schedule.bin");
  ASSERT_EQ(::mkfifo((broken / "schedule.bin").c_str(), 0600), 0);
  const reliability::CliResult r = reliability::run_bounded("optimize --resume broken --quiet", dir_);
  EXPECT_EQ(r.code, kExitInput) << r.output;
  EXPECT_EQ(r.output, "keyframe: error: broken/schedule.bin: not a regular file\n");
}

TEST_F(ScheduleReplayCli, AFlockRunStoresNone) {
  write("f.json", R"({"time": {"frames": 6}, "flock": {"agents": 3},
    "objectives": [{"type": "center_of_mass", "frame": 6, "target": [1, 0, 2]}],
    "controls": {"kind": "per_frame"}, "optimizer": {"max_evaluations": 2}})");
  ASSERT_TRUE(wrote_run(run_keyframe("optimize f.json --quiet --out flock", dir_).code));
  EXPECT_TRUE(fs::exists(dir_ / "flock/controls.bin"));
  EXPECT_FALSE(fs::exists(dir_ / "flock/schedule.bin"));
}

}  // namespace
}  // namespace kf
