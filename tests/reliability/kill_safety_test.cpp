// SIGKILL at any moment leaves a run directory whose every visible file is complete and valid: files are
// written to hidden temporaries and renamed, so a kill can leave only a hidden temporary, never a torn file.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <nlohmann/json.hpp>
#include <set>
#include <thread>

#include "cli_harness.h"
#include "core/error.h"
#include "core/trajectory.h"
#include "opt/evaluation_tape.h"
#include "render/image/png_io.h"

namespace kf::reliability {
namespace {

using Clock = std::chrono::steady_clock;

// Starts `keyframe ARGS...` in `cwd` with its output discarded; returns its pid.
pid_t spawn_keyframe(const fs::path& cwd, const std::vector<std::string>& args) {
  std::vector<std::string> argv_s = {KEYFRAME_BINARY};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (::chdir(cwd.c_str()) != 0) ::_exit(127);
    FILE* null = std::fopen("/dev/null", "w");
    if (null) {
      ::dup2(::fileno(null), 1);
      ::dup2(::fileno(null), 2);
    }
    std::vector<char*> argv;
    for (auto& s : argv_s) argv.push_back(s.data());
    argv.push_back(nullptr);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  return pid;
}

// Checks one result file is complete: it parses, loads or decodes as its kind says.
void expect_file_valid(const fs::path& file) {
  const std::string name = file.filename().string(), ext = file.extension().string();
  if (ext == ".json") {
    EXPECT_NO_THROW({ auto j = nlohmann::json::parse(read_text(file)); (void)j; });
  } else if (name == "trajectory.bin") {
    EXPECT_NO_THROW({ auto t = load_trajectory(file); (void)t; });
  } else if (name == "controls.bin") {
    const std::string b = read_text(file);
    ASSERT_GE(b.size(), 20u);
    EXPECT_EQ(b.substr(0, 8), "KFCTRL01");
    uint64_t n = 0;
    std::memcpy(&n, b.data() + 8, 8);
    EXPECT_EQ(b.size(), 20 + 8 * n);  // header: magic, count, substeps (opt/controls_file.h)
  } else if (name == "schedule.bin") {  // read against its scene and controls by the resume tests
    const std::string b = read_text(file);
    ASSERT_GE(b.size(), 8u);
    EXPECT_EQ(b.substr(0, 8), "KFSCHEDL");
  } else if (name == "evaluations.bin") {
    EXPECT_NO_THROW({ auto e = load_evaluations(file); (void)e; });
  } else if (ext == ".png") {
    EXPECT_NO_THROW({ auto img = render::read_png(file); (void)img; });
  } else if (ext == ".csv") {
    const std::string t = read_text(file);
    ASSERT_FALSE(t.empty());
    EXPECT_EQ(t.back(), '\n');
    std::istringstream in(t);
    std::string header, line;
    std::getline(in, header);
    const auto cols = std::count(header.begin(), header.end(), ',');
    int rows = 0;
    for (; std::getline(in, line); ++rows) EXPECT_EQ(std::count(line.begin(), line.end(), ','), cols) << line;
    EXPECT_GT(rows, 0);
  } else if (ext == ".txt") {
    const std::string t = read_text(file);
    ASSERT_FALSE(t.empty());
    EXPECT_EQ(t.back(), '\n');
  }
}

// Checks every visible file of a run directory; returns the names seen (hidden temporaries excluded).
std::set<std::string> expect_run_dir_valid(const fs::path& run, const std::string& when) {
  static const std::set<std::string> kKnown = {"scene.json",     "scene_name.txt", "controls.bin",
                                               "trajectory.bin", "iterations.csv", "convergence.png",
                                               "report.json",    "log.txt",        "frames",
                                               "evaluations.bin", "schedule.bin"};
  std::set<std::string> seen;
  if (!fs::exists(run)) return seen;
  for (const auto& e : fs::recursive_directory_iterator(run)) {
    const std::string name = e.path().filename().string();
    const std::string rel = fs::relative(e.path(), run).string();
    if (name.front() == '.') continue;  // a temporary that never got its final name: harmless
    SCOPED_TRACE(when + ": " + rel);
    if (e.path().parent_path() == run) {
      EXPECT_TRUE(kKnown.count(name)) << "unexpected file " << rel;
    }
    if (e.is_directory()) continue;
    seen.insert(rel);
    expect_file_valid(e.path());
  }
  return seen;
}

class KillSafety : public TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    // Long enough (about a second) that kills land in the optimisation, the saving and the rendering.
    write("f.json", R"({"seed": 3, "time": {"fps": 30, "frames": 40},
      "flock": {"agents": 60, "spawn": {"radius": 5, "velocity": [0, 0, 1]}},
      "objectives": [{"type": "center_of_mass", "frame": 40, "target": [1, 0, 4]}],
      "controls": {"kind": "per_step", "alpha": 0.01},
      "optimizer": {"max_evaluations": 20},
      "render": {"width": 48, "height": 32}})");
  }
  // Runs to completion once and returns its wall time.
  double full_run_seconds() {
    const auto t0 = Clock::now();
    const pid_t pid = spawn_keyframe(dir_, {"run", "f.json", "--quiet", "--out", "full"});
    int status = 0;
    ::waitpid(pid, &status, 0);
    // 20 evaluations do not reach the keyframe (exit 7, kExitNotReached); the run is rendered all the same.
    EXPECT_TRUE(WIFEXITED(status) && (WEXITSTATUS(status) == 0 || WEXITSTATUS(status) == 7)) << status;
    return std::chrono::duration<double>(Clock::now() - t0).count();
  }
};

TEST_F(KillSafety, CompleteRunIsValid) {
  full_run_seconds();
  const auto seen = expect_run_dir_valid(dir_ / "full", "complete run");
  for (const char* f : {"scene.json", "controls.bin", "trajectory.bin", "iterations.csv", "convergence.png",
                        "report.json", "log.txt", "frames/frame_0000.png"})
    EXPECT_TRUE(seen.count(f)) << f << " missing from a complete run";
}

TEST_F(KillSafety, SigkillAtManyMomentsLeavesOnlyValidFiles) {
  const double total = full_run_seconds();
  ASSERT_GT(total, 0.0);
  // Fractions of a full run's time, from before the run directory exists to the last frames.
  int killed_with_files = 0;
  for (double frac : {0.05, 0.3, 0.6, 0.8, 0.9, 0.97}) {
    const std::string out = "k" + std::to_string(int(frac * 100));
    const pid_t pid = spawn_keyframe(dir_, {"run", "f.json", "--quiet", "--out", out});
    std::this_thread::sleep_for(std::chrono::duration<double>(frac * total));
    ::kill(pid, SIGKILL);
    int status = 0;
    ::waitpid(pid, &status, 0);
    const auto seen = expect_run_dir_valid(dir_ / out, "killed at " + std::to_string(frac));
    if (!seen.empty()) ++killed_with_files;
  }
  EXPECT_GT(killed_with_files, 0) << "no kill landed after the run directory was created";
}

TEST_F(KillSafety, SigkillJustAsResultsAppear) {
  // Kill the moment each kind of result file first becomes visible: the window where a torn file would show.
  for (const char* trigger : {"controls.bin", "trajectory.bin", "iterations.csv", "report.json", "frames"}) {
    const std::string out = std::string("w_") + trigger;
    const pid_t pid = spawn_keyframe(dir_, {"run", "f.json", "--quiet", "--out", out});
    const auto deadline = Clock::now() + std::chrono::seconds(30);
    int status = 0;
    bool exited = false;
    while (Clock::now() < deadline && !fs::exists(dir_ / out / trigger)) {
      if (::waitpid(pid, &status, WNOHANG) == pid) {
        exited = true;
        break;
      }
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    if (!exited) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
    }
    expect_run_dir_valid(dir_ / out, std::string("killed when ") + trigger + " appeared");
  }
}

}  // namespace
}  // namespace kf::reliability
