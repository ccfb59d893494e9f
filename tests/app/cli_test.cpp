// The keyframe command as a user meets it: exit codes, one-line errors, nothing written on bad input.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.h"

namespace kf {
namespace {
namespace fs = std::filesystem;

struct Result {
  int code;
  std::string output;  // stdout and stderr together
};

Result run(const std::string& args, const fs::path& cwd) {
  const std::string cmd = "cd '" + cwd.string() + "' && '" KEYFRAME_BINARY "' " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  while (size_t n = fread(buf.data(), 1, buf.size(), p)) out.append(buf.data(), n);
  const int status = pclose(p);
  return {WEXITSTATUS(status), out};
}

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("keyframe_cli_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  void write(const std::string& name, const std::string& text) { std::ofstream(dir_ / name) << text; }
  fs::path dir_;
};

// The subcommands a user can reach. A subcommand added to the CLI and not here fails this test, as does one
// listed here that --help does not show or whose own --help fails.
const std::vector<std::string> kSubcommands = {"simulate", "optimize", "run",    "render",  "gradcheck", "figure",
                                               "bench",    "clip",     "export", "compare", "farm",     "inspect",
                                               "schema"};

TEST_F(Cli, HelpListsEverySubcommand) {
  const Result r = run("--help", dir_);
  ASSERT_EQ(r.code, 0);
  const size_t section = r.output.find("Subcommands:\n");
  ASSERT_NE(section, std::string::npos) << r.output;
  std::vector<std::string> listed;
  std::istringstream lines(r.output.substr(section + 13));
  for (std::string line; std::getline(lines, line);) {
    std::istringstream words(line);
    std::string name;
    if (line.rfind("  ", 0) == 0 && line.size() > 2 && line[2] != ' ' && (words >> name)) listed.push_back(name);
  }
  EXPECT_EQ(listed, kSubcommands);
  for (const std::string& sub : kSubcommands) {
    const Result h = run(sub + " --help", dir_);
    EXPECT_EQ(h.code, 0) << sub;
    EXPECT_NE(h.output.find("Usage:"), std::string::npos) << sub << ": " << h.output;
    EXPECT_NE(h.output.find(sub), std::string::npos) << sub;
  }
}

TEST_F(Cli, UnknownSubcommandIsAUsageError) {
  EXPECT_EQ(run("explode", dir_).code, kExitUsage);
  EXPECT_EQ(run("simulate", dir_).code, kExitUsage);  // SCENE missing
}

TEST_F(Cli, BadSceneGivesOneLineAndWritesNothing) {
  write("bad.json", R"({"time": {"fps": -1}, "flock": {"agents": 10}})");
  for (const char* cmd : {"simulate", "optimize", "run", "gradcheck"}) {
    const Result r = run(std::string(cmd) + " bad.json", dir_);
    EXPECT_EQ(r.code, kExitInput) << cmd << ": " << r.output;
    EXPECT_EQ(r.output, "keyframe: error: bad.json: /time/fps: expected a number in [1, 10000], got -1\n") << cmd;
    EXPECT_FALSE(fs::exists(dir_ / "out")) << cmd << " wrote output for a bad scene";
  }
}

TEST_F(Cli, MissingSceneFileIsNamed) {
  const Result r = run("simulate nowhere.json", dir_);
  EXPECT_EQ(r.code, kExitInput);
  EXPECT_EQ(r.output, "keyframe: error: nowhere.json: cannot open scene file\n");
}

// simulate runs the system forward only: what it prints and writes into report.json names no adjoint
// (System::describe names the one an optimisation would use) and says no gradient is taken.
TEST_F(Cli, SimulateDescribesAForwardRunWithoutAGradient) {
  for (const char* adjoint : {"exact", "swap"}) {
    write("cloth.json", std::string(R"({"time": {"fps": 30, "frames": 3},
      "cloth": {"nx": 4, "ny": 4, "width": 1, "height": 1, "pins": "top_corners"},
      "optimizer": {"adjoint": ")") + adjoint + R"("}})");
    const Result r = run("simulate cloth.json --out run", dir_);
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_EQ(r.output.rfind("simulated 3 steps forward (no controls, no gradient) of cloth: 4x4 particles, ", 0), 0u)
        << r.output;
    EXPECT_EQ(r.output.find("adjoint"), std::string::npos) << r.output;
    std::ifstream in(dir_ / "run/report.json");
    const std::string report((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(report.find("\"system\": \"cloth: 4x4 particles, "), std::string::npos) << report;
    EXPECT_NE(report.find("\"gradient\": false"), std::string::npos) << report;
    EXPECT_EQ(report.find("adjoint"), std::string::npos) << report;
  }
}

}  // namespace
}  // namespace kf
