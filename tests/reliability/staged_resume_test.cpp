// A staged run (a thrown sheet: the throw search, the rigid throw, the lattice, every particle; a sheet
// dropped on a sphere: lattice windows, then every particle) stopped by any of SIGINT, SIGTERM, SIGHUP,
// SIGQUIT in any of its stages and resumed ends exactly where an uninterrupted run ends: the same
// controls.bin and trajectory.bin bit for bit. A finished run resumed replays to its end without a new
// evaluation and exits as it did. A signal at start-up (planning, the throw search) exits 6 leaving nothing
// behind.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>
#include <tuple>

#include "../support/interrupted_run.h"
#include "app/optimize_job.h"
#include "cli_harness.h"
#include "core/error.h"

namespace kf::reliability {
namespace {

struct Signalled {
  int code = -1;
  std::string output;  // stdout
};

// Whether process `pid` has a handler for `sig` (/proc/PID/status, SigCgt).
bool catches(pid_t pid, int sig) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("SigCgt:", 0) == 0) return (std::stoull(line.substr(7), nullptr, 16) >> (sig - 1)) & 1;
  return false;
}

// Runs keyframe ARGS in `cwd`; when a stdout line starting with `trigger` appears (empty: never), or, with
// `when_handled`, as soon as the run has its handler for it, sends `sig` once.
Signalled run_and_signal(const fs::path& cwd, const std::vector<std::string>& args, const std::string& trigger = {},
                         int sig = SIGINT, bool when_handled = false) {
  test::KeyframeChild child = test::start_keyframe(cwd, args);
  const pid_t pid = child.pid;
  if (when_handled) {  // as soon as the process catches `sig` (its handler is installed), not before
    for (int k = 0; k < 20000 && !catches(pid, sig); ++k) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    ::kill(pid, sig);
  }
  char line[8192];
  Signalled r;
  bool signalled = false;
  while (std::fgets(line, sizeof line, child.out)) {
    const std::string s(line);
    r.output += s;
    if (!trigger.empty() && !signalled && s.rfind(trigger, 0) == 0) signalled = ::kill(pid, sig) == 0;
  }
  r.code = test::wait_for(child);
  return r;
}

nlohmann::json report_of(const fs::path& run) { return nlohmann::json::parse(read_text(run / "report.json")); }

// A 5 x 5 sheet thrown over a bar: a search over 16 rigid throws, then the rigid throw, a 3 x 3 lattice of
// velocities and one per particle (three stages).
const char* const kThrow = R"({"time": {"fps": 30, "frames": 20},
  "cloth": {"nx": 5, "ny": 5, "width": 0.4, "height": 0.4, "mass": 0.1, "origin": [-0.8, 0.5, -0.2],
            "u_axis": [1, 0, 0], "v_axis": [0, 0, 1], "velocity": [2.0, 2.0, 0],
            "colliders": [{"type": "capsule", "a": [0, 0.7, -0.6], "b": [0, 0.7, 0.6], "radius": 0.03},
                          {"type": "ground"}]},
  "objectives": [{"type": "center_of_mass", "frame": 20, "target": [0.5, 0.05, 0]}],
  "controls": {"kind": "initial_velocity"},
  "optimizer": {"max_evaluations": 24, "throw_search": 16}})";

// A 6 x 6 sheet dropped on a sphere with per-frame forces: lattice windows from frames 15, 10 and 0, then one
// force per particle (four stages; the budget gives each stage the twelve evaluations a planned window needs).
const char* const kDrop = R"({"time": {"fps": 30, "frames": 20},
  "cloth": {"nx": 6, "ny": 6, "width": 1.0, "height": 1.0, "mass": 0.3, "origin": [-0.5, 0.9, -0.5],
            "u_axis": [1, 0, 0], "v_axis": [0, 0, 1],
            "colliders": [{"type": "sphere", "center": [0, 0.5, 0], "radius": 0.3}, {"type": "ground"}]},
  "objectives": [{"type": "center_of_mass", "frame": 20, "target": [0.1, 0.5, 0]}],
  "controls": {"kind": "per_frame"},
  "optimizer": {"max_evaluations": 48, "stop_when_reached": false}})";  // every stage runs, to be cut

struct StagedCase {
  const char* name;
  const char* scene;
  int stages;
};

constexpr StagedCase kScenes[] = {{"throw", kThrow, 3}, {"drop", kDrop, 4}};

struct NamedSignal {
  const char* name;
  int sig;
};

constexpr NamedSignal kSignals[] = {{"sigint", SIGINT}, {"sigterm", SIGTERM}, {"sighup", SIGHUP}, {"sigquit", SIGQUIT}};

// One scene and one signal per case: every stage of the run interrupted by that signal and resumed.
class StagedResume : public TempDirTest, public ::testing::WithParamInterface<std::tuple<StagedCase, NamedSignal>> {};

TEST_P(StagedResume, InterruptedInEveryStageAndResumedEqualsUninterrupted) {
  const auto [c, signal] = GetParam();
  write("scene.json", c.scene);
  const Signalled whole = run_and_signal(dir_, {"optimize", "scene.json", "--out", "whole"});
  ASSERT_TRUE(whole.code == 0 || whole.code == kExitNotReached) << whole.code << whole.output;
  const auto whole_report = report_of(dir_ / "whole");
  ASSERT_EQ(whole_report.at("stages").get<int>(), c.stages) << whole.output;
  // Every stage runs: the keyframes of these scenes are not reached before the last one.
  const int ran = int(whole_report.at("stage_results").size());
  ASSERT_EQ(ran, c.stages) << whole.output;
  const std::string controls = read_text(dir_ / "whole/controls.bin");
  const std::string trajectory = read_text(dir_ / "whole/trajectory.bin");
  for (int s = 1; s <= ran; ++s) {
    const std::string out = "cut" + std::to_string(s);
    SCOPED_TRACE(out + " " + signal.name);
    const Signalled cut = run_and_signal(dir_, {"optimize", "scene.json", "--out", out},
                                         "stage " + std::to_string(s) + " eval ", signal.sig);
    ASSERT_EQ(cut.code, kExitInterrupted) << cut.output;
    const auto cut_report = report_of(dir_ / out);
    EXPECT_TRUE(cut_report.at("interrupted").get<bool>());
    // Stopped in stage s, not after it: the stages before it finished, stage s is the last one reported.
    EXPECT_EQ(int(cut_report.at("stage_results").size()), s);
    const int done = cut_report.at("evaluations").get<int>();
    EXPECT_LT(done, whole_report.at("evaluations").get<int>());
    const Signalled resumed = run_and_signal(dir_, {"optimize", "--resume", out});
    ASSERT_EQ(resumed.code, whole.code) << resumed.output;
    const auto r = report_of(dir_ / out);
    EXPECT_FALSE(r.at("interrupted").get<bool>());
    EXPECT_EQ(r.at("replayed_evaluations").get<int>(), done);
    EXPECT_EQ(r.at("evaluations"), whole_report.at("evaluations"));
    EXPECT_EQ(r.at("stage_results").size(), whole_report.at("stage_results").size());
    EXPECT_TRUE(read_text(dir_ / out / "controls.bin") == controls) << "controls differ";
    EXPECT_TRUE(read_text(dir_ / out / "trajectory.bin") == trajectory) << "trajectory differs";
  }
  // The finished run resumed: every evaluation replayed, none made, the same exit and files.
  const Signalled again = run_and_signal(dir_, {"optimize", "--resume", "whole"});
  EXPECT_EQ(again.code, whole.code) << again.output;
  const auto r = report_of(dir_ / "whole");
  EXPECT_EQ(r.at("replayed_evaluations"), whole_report.at("evaluations"));
  EXPECT_EQ(r.at("evaluations"), whole_report.at("evaluations"));
  EXPECT_TRUE(read_text(dir_ / "whole/controls.bin") == controls);
  EXPECT_TRUE(read_text(dir_ / "whole/trajectory.bin") == trajectory);
}

INSTANTIATE_TEST_SUITE_P(Scenes, StagedResume, ::testing::Combine(::testing::ValuesIn(kScenes), ::testing::ValuesIn(kSignals)),
                         [](const ::testing::TestParamInfo<std::tuple<StagedCase, NamedSignal>>& info) {
                           return std::string(std::get<0>(info.param).name) + "_" + std::get<1>(info.param).name;
                         });

// Nothing is left beside the output when a signal comes before the first evaluation.
void expect_nothing_written(const fs::path& dir) {
  std::vector<std::string> left;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename() != "scene.json") left.push_back(e.path().filename().string());
  EXPECT_TRUE(left.empty()) << left.size() << " entries, the first " << (left.empty() ? "" : left.front());
}

class StartUpSignals : public TempDirTest, public ::testing::WithParamInterface<int> {};

// A signal during the throw search (a bench's CPU limit among them) ends the run at the best throw flown: its
// run directory and report.json (no evaluation, interrupted), and nothing else beside the output.
TEST_P(StartUpSignals, DuringTheThrowSearchExitSixAndReportTheBestThrow) {
  std::string scene = kThrow;
  scene.replace(scene.find("\"throw_search\": 16"), 18, "\"throw_search\": 100000");
  write("scene.json", scene);
  const Signalled r = run_and_signal(dir_, {"optimize", "scene.json", "--out", "run"}, "stages: ", GetParam());
  EXPECT_EQ(r.code, kExitInterrupted) << r.output;
  std::vector<std::string> left;
  for (const auto& e : fs::directory_iterator(dir_))
    if (e.path().filename() != "scene.json" && e.path().filename() != "run") left.push_back(e.path().filename().string());
  EXPECT_TRUE(left.empty()) << left.size() << " entries, the first " << (left.empty() ? "" : left.front());
  std::ifstream in(dir_ / "run" / "report.json");
  ASSERT_TRUE(in) << r.output;
  const nlohmann::json report = nlohmann::json::parse(in);
  EXPECT_TRUE(report.at("interrupted").get<bool>());
  EXPECT_TRUE(report.contains("throw_search"));
}

TEST_P(StartUpSignals, DuringPlanningExitSixWithNothingWritten) {
  // A 20 x 20 sheet over 40 frames: the signal comes as the handlers are installed, before its growth probe
  // (one simulation and its adjoint, which then ends before the run does) is over.
  std::string scene = kDrop;
  scene.replace(scene.find("\"nx\": 6, \"ny\": 6"), 16, "\"nx\": 20, \"ny\": 20");
  scene.replace(scene.find("\"frames\": 20"), 12, "\"frames\": 40");
  write("scene.json", scene);
  const Signalled r = run_and_signal(dir_, {"optimize", "scene.json", "--out", "run"}, {}, GetParam(), true);
  EXPECT_EQ(r.code, kExitInterrupted) << r.output;
  expect_nothing_written(dir_);
}

INSTANTIATE_TEST_SUITE_P(Signals, StartUpSignals, ::testing::Values(SIGINT, SIGTERM, SIGHUP, SIGQUIT),
                         [](const ::testing::TestParamInfo<int>& info) { return "signal" + std::to_string(info.param); });

}  // namespace
}  // namespace kf::reliability
