#pragma once
// Running the real `keyframe` binary from tests: a private temp directory per test, the command's exit
// code and output, and a listing of what it left on disk.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

namespace kf::reliability {
namespace fs = std::filesystem;

struct CliResult {
  int code = -1;       // exit code, or -1 if the process did not exit normally (a crash)
  std::string output;  // stdout and stderr together
};

// Runs `COMMAND 2>&1` in `cwd` through the shell and collects what it prints.
inline CliResult run_in(const std::string& command, const fs::path& cwd) {
  const std::string cmd = "cd '" + cwd.string() + "' && " + command + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  while (size_t n = fread(buf.data(), 1, buf.size(), p)) out.append(buf.data(), n);
  const int status = pclose(p);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

// Runs `keyframe ARGS` in `cwd` through the shell (ARGS is pasted verbatim).
inline CliResult run_keyframe(const std::string& args, const fs::path& cwd) {
  return run_in("'" KEYFRAME_BINARY "' " + args, cwd);
}

// The same, killed after a minute, so that a hang fails the test instead of stalling it.
inline CliResult run_bounded(const std::string& args, const fs::path& cwd) {
  return run_in("timeout -s KILL 60 '" KEYFRAME_BINARY "' " + args, cwd);
}

// Every path under `dir`, relative and sorted; directories end in '/'.
inline std::vector<std::string> list_tree(const fs::path& dir) {
  std::vector<std::string> out;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator();
       it.increment(ec)) {
    std::string rel = fs::relative(it->path(), dir).string();
    if (it->is_directory()) rel += "/";
    out.push_back(rel);
  }
  std::sort(out.begin(), out.end());
  return out;
}

inline std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline void write_text(const fs::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

// A fresh directory under the system temp dir named after the running test; removed afterwards.
class TempDirTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::replace(name.begin(), name.end(), '/', '_');
    dir_ = fs::temp_directory_path() / ("keyframe_rel_" + std::to_string(::getpid()) + "_" + name);
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::permissions(dir_, fs::perms::owner_all, fs::perm_options::add, ec);
    fs::remove_all(dir_, ec);
  }
  void write(const std::string& name, const std::string& text) { write_text(dir_ / name, text); }
  fs::path dir_;
};

// Small scenes that optimise in well under a second.
inline std::string small_flock_scene(int frames = 20) {
  return R"({"seed": 3, "time": {"fps": 30, "frames": )" + std::to_string(frames) + R"(},
  "flock": {"agents": 12, "spawn": {"radius": 3, "velocity": [0, 0, 1]}},
  "objectives": [{"type": "center_of_mass", "frame": )" + std::to_string(frames) + R"(, "target": [1, 0, 2]}],
  "controls": {"kind": "per_frame", "alpha": 0.01},
  "optimizer": {"max_evaluations": 8},
  "render": {"width": 64, "height": 48}})";
}

inline std::string small_cloth_scene(int frames = 10) {
  return R"({"seed": 3, "time": {"fps": 30, "frames": )" + std::to_string(frames) + R"(},
  "cloth": {"nx": 5, "ny": 5, "width": 1, "height": 1, "pins": "top_corners"},
  "objectives": [{"type": "center_of_mass", "frame": )" + std::to_string(frames) + R"(, "target": [0.5, 0, 0.3]}],
  "controls": {"kind": "per_frame", "alpha": 0.01},
  "optimizer": {"max_evaluations": 6},
  "render": {"width": 64, "height": 48}})";
}

}  // namespace kf::reliability
