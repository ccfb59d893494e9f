// The numbers of the README and of the measurement report (tests/results/REPORT.md) against the committed
// results they come from. A value or table shown there is written as <!--gen:COMMAND-->TEXT<!--/gen--> (the
// comment is invisible on the rendered page); COMMAND runs in the repository root (usually scripts/result or
// a summary script over tests/results/) and TEXT must be what it prints. KEYFRAME_UPDATE_README=1 rewrites
// every TEXT from its command instead of checking.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/atomic_file.h"

namespace kf {
namespace {

const std::string kOpen = "<!--gen:", kClose = "<!--/gen-->";

struct Generated {
  std::string command;
  size_t text_begin = 0, text_end = 0;  // TEXT's byte range in the README
};

std::string trimmed(const std::string& s) {
  const size_t a = s.find_first_not_of(" \n\t"), b = s.find_last_not_of(" \n\t");
  return a == std::string::npos ? "" : s.substr(a, b - a + 1);
}

int line_of(const std::string& text, size_t pos) { return 1 + int(std::count(text.begin(), text.begin() + pos, '\n')); }

std::vector<Generated> generated_parts(const std::string& readme, const std::string& name = "README.md") {
  std::vector<Generated> out;
  for (size_t at = readme.find(kOpen); at != std::string::npos; at = readme.find(kOpen, at + 1)) {
    const size_t end_cmd = readme.find("-->", at);
    const size_t close = readme.find(kClose, at);
    const size_t next = readme.find(kOpen, at + 1);
    if (end_cmd == std::string::npos || close == std::string::npos || close < end_cmd ||
        (next != std::string::npos && next < close))
      throw std::runtime_error(name + ":" + std::to_string(line_of(readme, at)) + ": " + kOpen +
                               " without its " + kClose);
    const std::string command = readme.substr(at + kOpen.size(), end_cmd - at - kOpen.size());
    if (command.find("--") != std::string::npos)
      throw std::runtime_error(name + ":" + std::to_string(line_of(readme, at)) +
                               ": \"--\" ends an HTML comment early; use KEY=VALUE options");
    out.push_back({command, end_cmd + 3, close});
  }
  return out;
}

// stdout of `command` run in the repository root (once per test process); throws when it fails.
std::string output_of(const std::string& command) {
  static std::map<std::string, std::string> cache;
  if (auto it = cache.find(command); it != cache.end()) return it->second;
  const std::string cmd = "cd '" KEYFRAME_SOURCE_DIR "' && " + command;
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  while (size_t n = fread(buf.data(), 1, buf.size(), p)) out.append(buf.data(), n);
  if (pclose(p) != 0) throw std::runtime_error("`" + command + "` failed");
  return cache[command] = out;
}

// One line per value of `readme` (a file called `name`) that differs from its command's output.
std::vector<std::string> mismatches(const std::string& readme, const std::string& name = "README.md") {
  std::vector<std::string> out;
  for (const Generated& g : generated_parts(readme, name)) {
    const std::string shown = trimmed(readme.substr(g.text_begin, g.text_end - g.text_begin));
    const std::string wanted = trimmed(output_of(g.command));
    if (shown != wanted)
      out.push_back(name + ":" + std::to_string(line_of(readme, g.text_begin)) + ": shows \"" + shown +
                    "\" but `" + g.command + "` gives \"" + wanted + "\"");
  }
  return out;
}

// The README with every TEXT replaced by its command's output (tables keep a blank line on each side).
std::string regenerated(const std::string& readme) {
  std::string out;
  size_t copied = 0;
  for (const Generated& g : generated_parts(readme)) {
    out += readme.substr(copied, g.text_begin - copied);
    const std::string wanted = trimmed(output_of(g.command));
    const bool block = readme.compare(g.text_begin, 1, "\n") == 0;
    out += block ? "\n\n" + wanted + "\n\n" : wanted;
    copied = g.text_end;
  }
  return out + readme.substr(copied);
}

// The checked documents, from the repository root, with how many values each must at least hold (so that a
// lost marker block is noticed).
struct Document {
  const char* path;
  size_t min_values;
};
constexpr std::array<Document, 2> kDocuments{{{"README.md", 10}, {"tests/results/REPORT.md", 60}}};

std::string text_of(const std::string& path) {
  std::ifstream in(std::string(KEYFRAME_SOURCE_DIR "/") + path, std::ios::binary);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

TEST(Readme, EveryCheckedValueMatchesTheCommittedResults) {
  if (std::getenv("KEYFRAME_UPDATE_README")) {
    for (const Document& d : kDocuments)
      write_file_atomic(std::string(KEYFRAME_SOURCE_DIR "/") + d.path, regenerated(text_of(d.path)));
    GTEST_SKIP() << "rewrote README.md and tests/results/REPORT.md from their commands";
  }
  for (const Document& d : kDocuments) {
    const std::string text = text_of(d.path);
    ASSERT_FALSE(text.empty()) << d.path << " is missing";
    EXPECT_GE(generated_parts(text, d.path).size(), d.min_values) << d.path << "'s checked values have gone missing";
    for (const std::string& m : mismatches(text, d.path)) ADD_FAILURE() << m;
  }
}

TEST(Readme, AHandEditedValueOrAnUnclosedMarkerFails) {
  for (const Document& d : kDocuments) {
    const std::string text = text_of(d.path);
    const auto parts = generated_parts(text, d.path);
    ASSERT_FALSE(parts.empty()) << d.path;
    // Change the first digit of a checked value: each edit alone is caught.
    int edited = 0;
    for (const Generated& g : parts) {
      std::string copy = text;
      size_t digit = copy.find_first_of("0123456789", g.text_begin);
      if (digit == std::string::npos || digit >= g.text_end) continue;
      copy[digit] = copy[digit] == '9' ? '8' : char(copy[digit] + 1);
      const auto found = mismatches(copy, d.path);
      ASSERT_EQ(found.size(), 1u) << "an edit at " << d.path << ":" << line_of(text, digit) << " went unnoticed";
      EXPECT_EQ(found[0].rfind(std::string(d.path) + ":" + std::to_string(line_of(text, digit)) + ":", 0), 0u) << found[0];
      if (++edited == 3) break;  // each check runs every command: three edits a document are enough
    }
    EXPECT_EQ(edited, 3) << d.path;
  }
  EXPECT_THROW(generated_parts("a <!--gen:echo 1-->1 and no close"), std::runtime_error);
  EXPECT_THROW(generated_parts("<!--gen:scripts/result x.csv y --fmt %d-->1<!--/gen-->"), std::runtime_error);
  EXPECT_EQ(regenerated("x <!--gen:echo 2-->1<!--/gen--> y"), "x <!--gen:echo 2-->2<!--/gen--> y");
}

// One CSV record's fields (RFC 4180 quoting: "a, ""b""" is one field).
std::vector<std::string> csv_fields(const std::string& line) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted && c == '"' && i + 1 < line.size() && line[i + 1] == '"') out.back() += '"', ++i;
    else if (c == '"') quoted = !quoted;
    else if (c == ',' && !quoted) out.emplace_back();
    else out.back() += c;
  }
  return out;
}

// What is wrong with the stamps of the results under `dir` (its stamps.csv: file,date,commit,machine,
// load_1min,load,note): a file without a row, a row without date, commit, machine or load, a row for a
// file that is not there. README.md, REPORT.md and stamps.csv themselves need none.
std::vector<std::string> stamp_problems(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  std::vector<std::string> out;
  std::ifstream in(dir / "stamps.csv");
  std::string line;
  std::map<std::string, std::vector<std::string>> rows;
  if (!std::getline(in, line) || line != "file,date,commit,machine,load_1min,load,note")
    return {(dir / "stamps.csv").string() + ": missing or without its header"};
  while (std::getline(in, line)) {
    auto f = csv_fields(line);
    if (f.size() != 7) {
      out.push_back("stamps.csv: a row of " + std::to_string(f.size()) + " fields: " + line);
      continue;
    }
    for (int k : {1, 2, 3, 5})
      if (f[size_t(k)].empty()) out.push_back("stamps.csv: " + f[0] + " has no " + csv_fields("file,date,commit,machine,load_1min,load")[size_t(k)]);
    if (!fs::is_regular_file(dir / f[0])) out.push_back("stamps.csv: " + f[0] + " is not there");
    rows[f[0]] = f;
  }
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    const std::string rel = fs::relative(e.path(), dir).generic_string();
    if (rel != "README.md" && rel != "REPORT.md" && rel != "stamps.csv" && !rows.count(rel)) out.push_back(rel + " has no stamp in stamps.csv");
  }
  return out;
}

TEST(Readme, EveryCommittedResultIsStampedWithMachineCommitAndDate) {
  const auto problems = stamp_problems(KEYFRAME_SOURCE_DIR "/tests/results");
  for (const std::string& p : problems) ADD_FAILURE() << "tests/results/" << p << " (scripts/stamp FILE adds a row)";
}

TEST(Readme, AnUnstampedResultOrAStampForNoFileFails) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("keyframe_stamps_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" + std::to_string(std::rand()));
  fs::create_directories(dir / "runs/a");
  std::ofstream(dir / "runs/a/report.json") << "{}";
  std::ofstream(dir / "b.csv") << "x\n1\n";
  std::ofstream(dir / "stamps.csv") << "file,date,commit,machine,load_1min,load,note\n"
                                       "b.csv,2026-01-01,abc1234,\"vm: 2 CPU, 24 GB\",0.1,idle,\n";
  EXPECT_TRUE(stamp_problems(dir).size() == 1 && stamp_problems(dir)[0] == "runs/a/report.json has no stamp in stamps.csv");
  std::ofstream(dir / "stamps.csv", std::ios::app) << "runs/a/report.json,2026-01-01,,vm,0.1,idle,\ngone.csv,2026-01-01,abc,vm,,idle,\n";
  const auto problems = stamp_problems(dir);
  EXPECT_EQ(problems.size(), 2u);
  EXPECT_NE(std::find(problems.begin(), problems.end(), "stamps.csv: runs/a/report.json has no commit"), problems.end());
  EXPECT_NE(std::find(problems.begin(), problems.end(), "stamps.csv: gone.csv is not there"), problems.end());
  fs::remove_all(dir);
}

}  // namespace
}  // namespace kf
