// scenes/README.md documents every key the scene parser accepts, and names no key it does not.
//
// The keys are what the parser itself reads (ParamLog, the record behind `keyframe inspect SCENE`) over
// scenes that enter every branch: each objective type, collider shape, character block and optimizer stage.
// A scan of the parser's sources checks those scenes reach every key it names, so a key added to the parser
// and left out of these scenes fails here too.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "../reliability/cli_harness.h"
#include "scene/params.h"
#include "scene/scene.h"
#include "scene/scene_schema.h"

namespace kf {
namespace {

namespace fs = std::filesystem;

const fs::path kSource = KEYFRAME_SOURCE_DIR;

using reliability::read_text;

// Every key read (JSON pointers with array indices) over the example scenes the schema is generated from
// (src/scene/scene_schema.h), which enter every branch of the parser.
std::vector<ParamRead> reads_of_every_branch(const fs::path& dir) {
  std::vector<ParamRead> reads;
  for (const ParamLog& log : every_branch_logs(dir)) reads.insert(reads.end(), log.reads.begin(), log.reads.end());
  return reads;
}

// "/cloth/colliders/0/radius" -> {"cloth", "colliders", "radius"}: the keys along the pointer.
std::vector<std::string> keys_of(const std::string& pointer) {
  std::vector<std::string> keys;
  std::stringstream ss(pointer.substr(1));
  for (std::string part; std::getline(ss, part, '/');)
    if (!part.empty() && !std::all_of(part.begin(), part.end(), ::isdigit)) keys.push_back(part);
  return keys;
}

// The README split at its "## " headings; a heading's first code span names its block ("Top level": "").
struct Section {
  std::string block;
  std::vector<std::string> lines;
};

std::vector<std::string> code_spans(const std::string& line) {
  std::vector<std::string> spans;
  static const std::regex span("`([^`]*)`");
  for (std::sregex_iterator it(line.begin(), line.end(), span), end; it != end; ++it) spans.push_back((*it)[1]);
  return spans;
}

std::set<std::string> words_in(const std::string& text) {
  std::set<std::string> words;
  static const std::regex word("[$A-Za-z_][A-Za-z_0-9]*");  // "$schema" is a key
  for (std::sregex_iterator it(text.begin(), text.end(), word), end; it != end; ++it) words.insert(it->str());
  return words;
}

// The words inside the line's code spans: `{thickness, stiffness}`, `spawn.center` and `"a": [0,0,0]` all count.
std::set<std::string> code_words(const std::string& line) {
  std::set<std::string> words;
  for (const std::string& s : code_spans(line)) words.merge(words_in(s));
  return words;
}

std::map<std::string, Section> sections_of(const std::string& readme) {
  std::map<std::string, Section> sections;
  std::string current = "(preamble)";
  std::stringstream ss(readme);
  for (std::string line; std::getline(ss, line);) {
    if (line.rfind("## ", 0) == 0) {
      const auto spans = code_spans(line);
      current = spans.empty() ? "" : spans.front();
      if (line.find("Top level") != std::string::npos) current = "";
    }
    sections[current].block = current;
    sections[current].lines.push_back(line);
  }
  return sections;
}

// Which section documents a key, and the keys below that section's block that one of its lines must name:
// top-level keys and blocks without a section of their own ("time") are in "Top level".
std::pair<std::string, std::vector<std::string>> where_documented(const std::vector<std::string>& keys,
                                                                  const std::map<std::string, Section>& sections) {
  if (keys.size() > 1 && !keys.front().empty() && sections.count(keys.front()))
    return {keys.front(), std::vector<std::string>(keys.begin() + 1, keys.end())};
  return {"", keys};
}

// Each key the parser read that no line of its section names (all the keys along its pointer, in code
// spans on one line), and each string value it accepts that its section does not name, as "pointer: why".
std::vector<std::string> undocumented(const std::vector<ParamRead>& reads, const std::string& readme) {
  const auto sections = sections_of(readme);
  std::set<std::string> problems;
  for (const ParamRead& r : reads) {
    const auto [block, keys] = where_documented(keys_of(r.pointer), sections);
    const std::string section = block.empty() ? "Top level" : "`" + block + "`";
    const auto it = sections.find(block);
    if (it == sections.end()) {
      problems.insert(r.pointer + ": scenes/README.md has no " + section + " section");
      continue;
    }
    std::set<std::string> section_words;
    bool named = false;
    for (const std::string& line : it->second.lines) {
      const auto words = code_words(line);
      section_words.insert(words.begin(), words.end());
      named = named || std::all_of(keys.begin(), keys.end(), [&](const std::string& k) { return words.count(k); });
    }
    if (!named) problems.insert(r.pointer + ": no line of the " + section + " section names it");
    for (const std::string& choice : r.choices)
      if (!section_words.count(choice))
        problems.insert(r.pointer + ": the value \"" + choice + "\" is not named in the " + section + " section");
  }
  return {problems.begin(), problems.end()};
}

// The reverse: each key in the first column of a section's key table (type in the objectives table) that the
// parser does not read in that section's block.
std::vector<std::string> documented_but_not_read(const std::vector<ParamRead>& reads, const std::string& readme) {
  const auto sections = sections_of(readme);
  std::map<std::string, std::set<std::string>> read_words;  // section block -> keys read below it
  std::set<std::string> types;
  for (const ParamRead& r : reads) {
    const auto [block, keys] = where_documented(keys_of(r.pointer), sections);
    read_words[block].insert(keys.begin(), keys.end());
    if (keys_of(r.pointer) == std::vector<std::string>{"objectives", "type"}) types.insert(r.choices.begin(), r.choices.end());
  }
  std::vector<std::string> problems;
  for (const auto& [block, section] : sections) {
    std::string header;  // the first cell of the current table's header
    for (const std::string& line : section.lines) {
      if (line.rfind("|", 0) != 0) {
        header.clear();
        continue;
      }
      const std::string first = line.substr(1, line.find('|', 1) - 1);
      if (header.empty()) {
        header = words_in(first).empty() ? "" : *words_in(first).begin();
        continue;
      }
      if (header != "key" && header != "type") continue;
      for (const std::string& span : code_spans(first))
        for (const std::string& word : words_in(span)) {
          const bool known = header == "type" ? types.count(word) > 0 : read_words[block].count(word) > 0;
          if (!known)
            problems.push_back("`" + word + "` in the " + (block.empty() ? "Top level" : "`" + block + "`") +
                               " table is not a key the parser reads there");
        }
    }
  }
  return problems;
}

// Every key literal the parser's sources pass to a Block read or check: b.number("fps", ...),
// unit_vec3(b, "axis", ...), b.fail("type", ...).
std::set<std::string> keys_named_in_parser_sources() {
  std::set<std::string> keys;
  static const std::regex call(R"(\w+\((?:\w+,\s*)?"([a-z][a-z0-9_]*)\")");
  for (const auto& entry : fs::directory_iterator(kSource / "src/scene")) {
    const std::string name = entry.path().filename().string();
    if (!(name == "scene.cpp" || (name.size() > 9 && name.substr(name.size() - 9) == "_spec.cpp"))) continue;
    const std::string text = read_text(entry.path());
    for (std::sregex_iterator it(text.begin(), text.end(), call), end; it != end; ++it) keys.insert((*it)[1]);
  }
  return keys;
}

class SceneDocs : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("keyframe_scene_docs_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    reads_ = reads_of_every_branch(dir_);
    readme_ = read_text(kSource / "scenes/README.md");
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
  std::vector<ParamRead> reads_;
  std::string readme_;
};

TEST_F(SceneDocs, TheScenesReachEveryKeyTheParserNames) {
  std::set<std::string> read;
  for (const ParamRead& r : reads_) read.insert(keys_of(r.pointer).back());
  EXPECT_GT(read.size(), 100u);
  for (const std::string& key : keys_named_in_parser_sources())
    EXPECT_TRUE(read.count(key)) << "\"" << key << "\" is named in src/scene but no scene of this test reads it";
}

TEST_F(SceneDocs, ReadmeDocumentsEveryKeyTheParserReads) {
  const auto missing = undocumented(reads_, readme_);
  for (const std::string& m : missing) ADD_FAILURE() << "scenes/README.md: " << m;
  EXPECT_TRUE(missing.empty()) << missing.size() << " keys or values undocumented";
}

TEST_F(SceneDocs, ReadmeTablesNameOnlyKeysTheParserReads) {
  for (const std::string& p : documented_but_not_read(reads_, readme_)) ADD_FAILURE() << "scenes/README.md: " << p;
}

// The checks find what they are for: a key's row removed, a block's key misspelt in its table.
TEST_F(SceneDocs, ChecksFindARemovedRowAndAMisspeltKey) {
  auto without = [&](const std::string& text, const std::string& line_start) {
    std::stringstream in(text), out;
    for (std::string line; std::getline(in, line);)
      if (line.rfind(line_start, 0) != 0) out << line << "\n";
    return out.str();
  };
  const auto missing = undocumented(reads_, without(readme_, "| `ftol_rel` |"));
  ASSERT_EQ(missing.size(), 1u);
  EXPECT_EQ(missing.front(), "/optimizer/ftol_rel: no line of the `optimizer` section names it");

  std::string misspelt = readme_;
  misspelt.replace(misspelt.find("| `contact_ramp` |"), 18, "| `contact_rmap` |");
  const auto extra = documented_but_not_read(reads_, misspelt);
  ASSERT_EQ(extra.size(), 1u);
  EXPECT_EQ(extra.front(), "`contact_rmap` in the `cloth` table is not a key the parser reads there");
  EXPECT_EQ(undocumented(reads_, misspelt).front(), "/cloth/contact_ramp: no line of the `cloth` section names it");
}

}  // namespace
}  // namespace kf
