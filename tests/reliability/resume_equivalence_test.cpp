// An optimisation interrupted by a signal and resumed ends exactly where an uninterrupted one ends: the
// same controls bit for bit, the same evaluations, one iterations.csv. Every stopping signal saves like
// SIGINT, the report says "interrupted", and --max-evaluations is a hard limit.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstring>
#include <nlohmann/json.hpp>

#include "../support/interrupted_run.h"
#include "app/optimize_job.h"
#include "cli_harness.h"
#include "core/error.h"

namespace kf::reliability {
namespace {

// Runs keyframe ARGS in `cwd`; after `signal_after` evaluation lines on stdout, sends `sig` (0: never).
int run_and_signal(const fs::path& cwd, const std::vector<std::string>& args, int signal_after = 0, int sig = SIGINT) {
  test::KeyframeChild child = test::start_keyframe(cwd, args);
  char line[4096];
  int evals = 0;
  bool signalled = false;
  while (std::fgets(line, sizeof line, child.out)) {
    const std::string s(line);
    if (s.rfind("eval ", 0) == 0 || s.find(" eval ") != std::string::npos) ++evals;
    // Once: lines printed after it (the interruption's own) must not signal again, when the run may have
    // left its handler and a second signal would kill it.
    if (signal_after > 0 && evals == signal_after && !signalled) signalled = ::kill(child.pid, sig) == 0;
  }
  return test::wait_for(child);
}

nlohmann::json report_of(const fs::path& run) { return nlohmann::json::parse(read_text(run / "report.json")); }

// iterations.csv without its seconds column (the only thing that may differ between two runs).
std::string iterations_without_seconds(const fs::path& run) {
  std::istringstream in(read_text(run / "iterations.csv"));
  std::string line, out;
  while (std::getline(in, line)) {
    const size_t a = line.find(','), b = line.find(',', a + 1);
    out += line.substr(0, a) + line.substr(b) + "\n";
  }
  return out;
}

class ResumeEquivalence : public TempDirTest, public ::testing::WithParamInterface<const char*> {};

TEST_P(ResumeEquivalence, InterruptedAndResumedEqualsUninterrupted) {
  const std::string scene = std::string(KEYFRAME_SOURCE_DIR) + "/scenes/" + GetParam() + ".json";
  const std::vector<std::string> common = {"--max-evaluations", "12"};
  auto args = [&](const std::vector<std::string>& a) {
    std::vector<std::string> all = a;
    all.insert(all.end(), common.begin(), common.end());
    return all;
  };
  // A budget of 12 may stop short of the keyframes (kExitNotReached): the resumed run must end the same way.
  const int whole_code = run_and_signal(dir_, args({"optimize", scene, "--out", "whole"}));
  ASSERT_TRUE(whole_code == 0 || whole_code == kExitNotReached) << whole_code;
  ASSERT_EQ(run_and_signal(dir_, args({"optimize", scene, "--out", "cut"}), 5), kExitInterrupted);
  const auto cut = report_of(dir_ / "cut");
  EXPECT_TRUE(cut.at("interrupted").get<bool>());
  EXPECT_EQ(cut.at("status").get<std::string>(), "interrupted");
  const int done = cut.at("evaluations").get<int>();
  EXPECT_GE(done, 5);
  EXPECT_LT(done, 12);
  ASSERT_EQ(run_and_signal(dir_, args({"optimize", "--resume", "cut"})), whole_code);
  const auto whole = report_of(dir_ / "whole"), resumed = report_of(dir_ / "cut");
  EXPECT_EQ(resumed.at("replayed_evaluations").get<int>(), done);
  EXPECT_EQ(resumed.at("evaluations"), whole.at("evaluations"));
  EXPECT_EQ(resumed.at("status"), whole.at("status"));
  EXPECT_EQ(resumed.at("final_objective"), whole.at("final_objective"));
  EXPECT_EQ(read_text(dir_ / "cut/controls.bin"), read_text(dir_ / "whole/controls.bin")) << "controls differ";
  EXPECT_EQ(read_text(dir_ / "cut/trajectory.bin"), read_text(dir_ / "whole/trajectory.bin"));
  EXPECT_EQ(iterations_without_seconds(dir_ / "cut"), iterations_without_seconds(dir_ / "whole"));
}

INSTANTIATE_TEST_SUITE_P(Scenes, ResumeEquivalence, ::testing::Values("arch", "square"));

class StopSignals : public TempDirTest, public ::testing::WithParamInterface<int> {};

TEST_P(StopSignals, SaveTheRunAndSayInterrupted) {
  write("f.json", R"({"seed": 3, "time": {"fps": 30, "frames": 30},
    "flock": {"agents": 40, "spawn": {"radius": 4, "velocity": [0, 0, 1]}},
    "objectives": [{"type": "center_of_mass", "frame": 30, "target": [2, 0, 3]}],
    "controls": {"kind": "per_step", "alpha": 0.001}, "optimizer": {"max_evaluations": 200, "ftol_rel": 1e-14}})");
  EXPECT_EQ(run_and_signal(dir_, {"optimize", "f.json", "--out", "run"}, 2, GetParam()), kExitInterrupted);
  const auto r = report_of(dir_ / "run");
  EXPECT_TRUE(r.at("interrupted").get<bool>());
  EXPECT_EQ(r.at("status").get<std::string>(), "interrupted");
  for (const char* f : {"controls.bin", "trajectory.bin", "evaluations.bin", "iterations.csv", "scene.json"})
    EXPECT_TRUE(fs::exists(dir_ / "run" / f)) << f;
  // Four evaluations do not reach the keyframe: the resumed run is written and says so.
  EXPECT_EQ(run_and_signal(dir_, {"optimize", "--resume", "run", "--max-evaluations", "4"}), kExitNotReached);
}

INSTANTIATE_TEST_SUITE_P(Signals, StopSignals, ::testing::Values(SIGINT, SIGTERM, SIGHUP, SIGQUIT),
                         [](const ::testing::TestParamInfo<int>& info) { return std::string(strsignal(info.param)).substr(0, 4) + std::to_string(info.param); });

class EvaluationLimit : public TempDirTest, public ::testing::WithParamInterface<const char*> {};

TEST_P(EvaluationLimit, MaxEvaluationsIsAHardLimit) {
  const std::string scene = std::string(KEYFRAME_SOURCE_DIR) + "/scenes/" + GetParam() + ".json";
  ASSERT_EQ(run_and_signal(dir_, {"optimize", scene, "--out", "run", "--max-evaluations", "3"}), kExitNotReached);
  const auto r = report_of(dir_ / "run");
  EXPECT_EQ(r.at("evaluations").get<int>(), 3);
  EXPECT_EQ(r.at("status").get<std::string>(), "evaluation limit reached");
  const std::string csv = read_text(dir_ / "run/iterations.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 4) << csv;  // header and three evaluations
}

INSTANTIATE_TEST_SUITE_P(Scenes, EvaluationLimit, ::testing::Values("arch", "square"));

}  // namespace
}  // namespace kf::reliability
