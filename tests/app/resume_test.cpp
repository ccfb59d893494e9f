// Interrupting an optimisation with SIGINT saves the best controls; --resume finishes the job.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "app/optimize_job.h"
#include "core/error.h"

namespace kf {
namespace {
namespace fs = std::filesystem;

const char* kScene = R"({
  "seed": 3,
  "time": {"fps": 30, "frames": 60},
  "flock": {"agents": 100, "spawn": {"radius": 7, "velocity": [0, 0, 1]}},
  "objectives": [
    {"type": "center_of_mass", "frame": 30, "target": [2, 0, 2]},
    {"type": "center_of_mass", "frame": 60, "target": [0, 0, 5]}
  ],
  "controls": {"kind": "per_step", "alpha": 0.001},
  "optimizer": {"max_evaluations": 400, "ftol_rel": 1e-12, "soft_keyframes": true, "stop_when_reached": false}
})";

// Runs keyframe with args in dir; when interrupt_after_lines > 0, sends SIGINT after that many lines.
int run_keyframe(const fs::path& dir, const std::vector<std::string>& args, int interrupt_after_lines = 0) {
  int fds[2];
  EXPECT_EQ(pipe(fds), 0);
  const pid_t pid = fork();
  if (pid == 0) {
    dup2(fds[1], STDOUT_FILENO);
    close(fds[0]);
    if (chdir(dir.c_str()) != 0) _exit(120);
    std::vector<char*> argv{const_cast<char*>(KEYFRAME_BINARY)};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(KEYFRAME_BINARY, argv.data());
    _exit(127);
  }
  close(fds[1]);
  FILE* out = fdopen(fds[0], "r");
  char line[4096];
  int lines = 0;
  while (fgets(line, sizeof line, out)) {
    if (std::string(line).find(" eval ") != std::string::npos || std::string(line).rfind("eval", 0) == 0) ++lines;
    if (interrupt_after_lines > 0 && lines == interrupt_after_lines) kill(pid, SIGINT);
  }
  fclose(out);
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

double final_objective(const fs::path& run) {
  std::ifstream in(run / "report.json");
  return nlohmann::json::parse(in).at("final_objective").get<double>();
}

TEST(Resume, InterruptedThenResumedRunMatchesAnUninterruptedOne) {
  const fs::path dir = fs::temp_directory_path() / ("keyframe_resume_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "small.json") << kScene;

  // The flock converges short of its keyframes (exit 7, kExitNotReached; soft keyframes and no stop rule, so
  // the run is one stage polished to convergence); what is compared is the objective.
  const int whole_code = run_keyframe(dir, {"optimize", "small.json", "--out", "whole"});
  ASSERT_TRUE(whole_code == 0 || whole_code == kExitNotReached) << whole_code;
  const double whole = final_objective(dir / "whole");

  EXPECT_EQ(run_keyframe(dir, {"optimize", "small.json", "--out", "cut"}, 3), kExitInterrupted);
  std::ifstream report(dir / "cut" / "report.json");
  const auto j = nlohmann::json::parse(report);
  EXPECT_TRUE(j.at("interrupted").get<bool>());
  const double at_cut = j.at("final_objective").get<double>();
  EXPECT_GT(at_cut, whole * 1.01) << "the interrupted run had already converged; interrupt earlier";

  EXPECT_EQ(run_keyframe(dir, {"optimize", "--resume", "cut"}), whole_code);
  const double resumed = final_objective(dir / "cut");
  EXPECT_LT(resumed, at_cut);
  EXPECT_NEAR(resumed, whole, 1e-3 * whole + 1e-9) << "uninterrupted " << whole << ", resumed " << resumed;
  if (!HasFailure()) fs::remove_all(dir);
}

}  // namespace
}  // namespace kf
