// The README's "Your first scene", run as a reader would run it: each "Save this as `NAME`:" JSON block is
// written to NAME and each ```sh block is run, in order, in a fresh directory with keyframe on PATH. Then
// the files those commands promise are checked: the keyframes met, the frames drawn, the figure, the
// identical frames of the one-thread run, the exported glTF.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "../reliability/cli_harness.h"
#include "render/image/png_io.h"

namespace kf {
namespace {

namespace fs = std::filesystem;
using reliability::read_text;

struct WalkthroughScript {
  std::vector<std::pair<std::string, std::string>> files;  // name, JSON text
  std::vector<std::string> command_blocks;
  std::string script;  // files and commands in the README's order, as one bash script
};

// The section "## Your first scene" of `readme`, up to the next second-level heading.
std::string first_scene_section(const std::string& readme) {
  const size_t a = readme.find("\n## Your first scene\n");
  if (a == std::string::npos) return "";
  const size_t b = readme.find("\n## ", a + 1);
  return readme.substr(a, b == std::string::npos ? std::string::npos : b - a);
}

WalkthroughScript parse_walkthrough(const std::string& section) {
  WalkthroughScript w;
  // A fenced block and what precedes it since the previous block.
  const std::regex block(R"(```(json|sh)\n([\s\S]*?)```)");
  const std::regex save(R"(Save this as\s+`([^`]+)`:\s*$)");
  size_t prev_end = 0;
  for (auto it = std::sregex_iterator(section.begin(), section.end(), block); it != std::sregex_iterator(); ++it) {
    const std::string kind = (*it)[1], body = (*it)[2];
    const std::string before = section.substr(prev_end, size_t(it->position()) - prev_end);
    prev_end = size_t(it->position() + it->length());
    if (kind == "json") {
      std::smatch m;
      if (!std::regex_search(before, m, save)) throw std::runtime_error("a JSON block without \"Save this as `NAME`:\"");
      w.files.emplace_back(m[1], body);
      w.script += "cat > '" + m[1].str() + "' <<'KEYFRAME_EOF'\n" + body + "KEYFRAME_EOF\n";
    } else {
      w.command_blocks.push_back(body);
      w.script += body;
    }
  }
  return w;
}

std::string readme() { return read_text(KEYFRAME_SOURCE_DIR "/README.md"); }

class Walkthrough : public reliability::TempDirTest {};

TEST_F(Walkthrough, TheReadmeHasScenesAndCommandsToRun) {
  const WalkthroughScript w = parse_walkthrough(first_scene_section(readme()));
  ASSERT_EQ(w.files.size(), 2u);
  EXPECT_EQ(w.files[0].first, "my-flock.json");
  EXPECT_EQ(w.files[1].first, "my-cloth.json");
  for (const auto& [name, text] : w.files) EXPECT_TRUE(nlohmann::json::accept(text)) << name;
  EXPECT_GE(w.command_blocks.size(), 3u);
  EXPECT_THROW(parse_walkthrough("some text\n```json\n{}\n```\n"), std::runtime_error);
}


nlohmann::json json_of(const fs::path& p) { return nlohmann::json::parse(read_text(p)); }

// The fraction of pixels of `a` and `b` (same size) that differ.
double differing_fraction(const render::Image& a, const render::Image& b) {
  size_t differ = 0;
  for (size_t i = 0; i < a.pixels.size(); i += size_t(a.channels))
    differ += !std::equal(a.pixels.begin() + long(i), a.pixels.begin() + long(i) + a.channels, b.pixels.begin() + long(i));
  return double(differ) / double(a.width * a.height);
}

TEST_F(Walkthrough, EveryCommandOfTheReadmeRuns) {
  const WalkthroughScript w = parse_walkthrough(first_scene_section(readme()));
  write("walkthrough.sh", "set -euo pipefail\n" + w.script);
  const std::string bin_dir = fs::path(KEYFRAME_BINARY).parent_path().string();
  const std::string cmd = "cd '" + dir_.string() + "' && PATH='" + bin_dir + "':\"$PATH\" bash walkthrough.sh 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  char buf[4096];
  while (size_t n = fread(buf, 1, sizeof buf, p)) out.append(buf, n);
  ASSERT_EQ(pclose(p), 0) << out;

  // The flock: every agent inside the triangle at its keyframe, most of the triangle covered.
  const auto flock = json_of(dir_ / "out/my-flock/report.json");
  EXPECT_GE(flock["measures"][0]["inside_fraction"].get<double>(), 0.95) << flock.dump();
  EXPECT_GE(flock["measures"][0]["coverage_fraction"].get<double>(), 0.8) << flock.dump();
  const auto f0 = render::read_png(dir_ / "out/my-flock/frames/frame_0000.png");
  const auto f45 = render::read_png(dir_ / "out/my-flock/frames/frame_0045.png");
  EXPECT_EQ(f0.width, 480);
  EXPECT_EQ(f0.height, 270);
  EXPECT_FALSE(fs::exists(dir_ / "out/my-flock/frames/frame_0046.png"));
  EXPECT_GT(differing_fraction(f0, f45), 0.01) << "the flock did not move on screen";

  // The cloth: both corners within 2 cm of their targets at frame 30, and the frames drawn.
  const auto cloth = json_of(dir_ / "out/my-cloth/report.json");
  EXPECT_LT(cloth["measures"][0]["rms_error"].get<double>(), 0.02) << cloth.dump();
  const auto c0 = render::read_png(dir_ / "out/my-cloth/frames/frame_0000.png");
  const auto c30 = render::read_png(dir_ / "out/my-cloth/frames/frame_0030.png");
  EXPECT_GT(differing_fraction(c0, c30), 0.01) << "the sheet did not move on screen";

  // The figure sheet, as PNG and PDF.
  const auto sheet = render::read_png(dir_ / "out/figures/first-scenes.png");
  EXPECT_GT(sheet.width, 2 * 320);
  EXPECT_GT(sheet.height, 2 * 180);
  EXPECT_EQ(read_text(dir_ / "out/figures/first-scenes.pdf").substr(0, 5), "%PDF-");

  // One thread against all cores: the same pixels, and compare said so.
  for (int f : {0, 20, 45}) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%04d.png", f);
    const auto a = render::read_png(dir_ / "out/my-flock/frames" / name);
    const auto b = render::read_png(dir_ / "out/my-flock-1-thread/frames" / name);
    EXPECT_EQ(a.pixels, b.pixels) << name;
  }
  EXPECT_EQ(read_text(dir_ / "out/my-flock/trajectory.bin"), read_text(dir_ / "out/my-flock-1-thread/trajectory.bin"));
  const auto compared = json_of(dir_ / "out/my-flock-1-thread/compare/compare.json");
  EXPECT_EQ(compared["frames_compared"].get<int>(), 46);
  EXPECT_EQ(compared["frames_failed"].get<int>(), 0);

  // The export: one mesh moving through 31 frames.
  const auto gltf = json_of(dir_ / "out/my-cloth/export/my-cloth.gltf");
  ASSERT_EQ(gltf["meshes"].size(), 1u) << gltf.dump().substr(0, 2000);
  EXPECT_EQ(gltf["meshes"][0]["primitives"][0]["targets"].size(), 31u);
  EXPECT_EQ(gltf["animations"].size(), 1u);
  EXPECT_TRUE(fs::exists(dir_ / "out/my-cloth/export/my-cloth.bin"));
}

// `keyframe compare --help`'s example, line by line, on a small run called "square": each command works.
TEST_F(Walkthrough, CompareHelpsExampleRuns) {
  auto help = reliability::run_keyframe("compare --help", dir_);
  ASSERT_EQ(help.code, 0) << help.output;
  const size_t at = help.output.find("Example:\n");
  ASSERT_NE(at, std::string::npos) << help.output;
  std::istringstream lines(help.output.substr(at + 9));
  std::vector<std::string> commands;
  for (std::string line; std::getline(lines, line) && line.rfind("  keyframe ", 0) == 0;)
    commands.push_back(line.substr(11, line.find('#') == std::string::npos ? std::string::npos : line.find('#') - 11));
  ASSERT_EQ(commands.size(), 3u) << help.output;
  write("square.json", reliability::small_flock_scene(6));
  ASSERT_EQ(reliability::run_keyframe("simulate square.json", dir_).code, 0);
  for (const std::string& c : commands) {
    const auto r = reliability::run_keyframe(c, dir_);
    EXPECT_EQ(r.code, 0) << c << "\n" << r.output;
  }
  EXPECT_TRUE(fs::exists(dir_ / "refs/square/frame_0006.png"));
}

}  // namespace
}  // namespace kf
