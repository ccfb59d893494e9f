// No function body in src/ or render/ is longer than 60 lines: a longer one is split into named steps.
// Function bodies are found by a simple heuristic: comments, string and character literals are blanked,
// a line ending in `) {` (optionally with const, noexcept, a trailing return type or override) that opens
// a brace outside any function starts a body, and the body ends where the braces balance again. Its
// length counts the line with the opening brace through the line with the closing one.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace kf {
namespace {

namespace fs = std::filesystem;

constexpr int kMaxLines = 60;

struct LongFunction {
  std::string file;
  int line = 0;    // 1-based, the line with the opening brace
  int length = 0;  // lines
};

bool identifier_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

// `text` with comments removed and string and character literals emptied, line breaks kept.
std::vector<std::string> code_lines(const std::string& text) {
  std::string out;
  size_t i = 0;
  const size_t n = text.size();
  // Skips a literal that started at i (the opening quote) up to its closing quote.
  const auto skip_quoted = [&](char quote) {
    for (++i; i < n && text[i] != quote && text[i] != '\n'; ++i)
      if (text[i] == '\\') ++i;
  };
  for (; i < n; ++i) {
    const char c = text[i];
    if (c == '/' && i + 1 < n && text[i + 1] == '/') {
      while (i + 1 < n && text[i + 1] != '\n') ++i;
    } else if (c == '/' && i + 1 < n && text[i + 1] == '*') {
      for (i += 2; i + 1 < n && !(text[i] == '*' && text[i + 1] == '/'); ++i)
        if (text[i] == '\n') out += '\n';
      ++i;
    } else if (c == 'R' && i + 1 < n && text[i + 1] == '"' && (i == 0 || !identifier_char(text[i - 1]))) {
      const size_t open = text.find('(', i + 2);
      const std::string close = ")" + text.substr(i + 2, open - (i + 2)) + "\"";
      const size_t end = text.find(close, open);
      const size_t stop = end == std::string::npos ? n : end + close.size();
      out += "\"\"";
      out.append(size_t(std::count(text.begin() + long(i), text.begin() + long(stop), '\n')), '\n');
      i = stop - 1;
    } else if (c == '"') {
      skip_quoted('"');
      out += "\"\"";
    } else if (c == '\'' && (i == 0 || !std::isxdigit(static_cast<unsigned char>(text[i - 1])))) {
      skip_quoted('\'');  // a character literal, not a digit separator
      out += "''";
    } else {
      out += c;
    }
  }
  std::vector<std::string> lines;
  std::istringstream in(out);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// Function bodies of the source `text` longer than `max_lines`, with `file` as their file name.
std::vector<LongFunction> long_functions(const std::string& file, const std::string& text, int max_lines) {
  static const std::regex opens_body(R"(\)\s*(const)?\s*(noexcept)?\s*(->[^{]*)?(override)?\s*\{\s*$)");
  static const std::regex statement(R"(^\s*(if|for|while|switch|else|do)\b)");
  static const std::regex type_or_namespace(R"(\b(namespace|struct|class|enum)\b)");
  std::vector<LongFunction> out;
  const std::vector<std::string> lines = code_lines(text);
  int depth = 0, start = -1, start_depth = 0;
  for (int i = 0; i < int(lines.size()); ++i) {
    const std::string& s = lines[size_t(i)];
    const int opens = int(std::count(s.begin(), s.end(), '{')), closes = int(std::count(s.begin(), s.end(), '}'));
    if (start < 0 && opens > closes && std::regex_search(s, opens_body) && !std::regex_search(s, statement) &&
        !std::regex_search(s, type_or_namespace)) {
      start = i;
      start_depth = depth;
    }
    depth += opens - closes;
    if (start >= 0 && depth <= start_depth) {
      const int length = i - start + 1;
      if (length > max_lines) out.push_back({file, start + 1, length});
      start = -1;
    }
  }
  return out;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// A function of `body_lines` lines (brace to brace) between others, with braces in literals and comments.
std::string sample_source(int body_lines) {
  std::string s = "namespace kf {\n// a { in a comment\nint small(int a) {\n  return a;\n}\n\n";
  s += "int long_one(int a) {\n";
  for (int k = 0; k < body_lines - 2; ++k) s += "  a += 1;  // }\n";
  s += "}\n\nconst char* braces() {\n  const char c = '{';\n  return \"}}\" + c;\n}\n";
  s += "const char* raw() {\n  return R\"x(\n}\n})x\";\n}\n}  // namespace kf\n";
  return s;
}

TEST(FunctionLength, HeuristicFindsTheLongFunctionOnly) {
  const std::vector<LongFunction> at_limit = long_functions("sample.cpp", sample_source(kMaxLines), kMaxLines);
  EXPECT_TRUE(at_limit.empty()) << at_limit.size() << " found, the first " << at_limit.front().length << " lines";
  const std::vector<LongFunction> over = long_functions("sample.cpp", sample_source(kMaxLines + 1), kMaxLines);
  ASSERT_EQ(over.size(), 1u);
  EXPECT_EQ(over[0].line, 7);
  EXPECT_EQ(over[0].length, kMaxLines + 1);
  // Every function of the sample, whatever its length, is seen as one body that closes where it should.
  const std::vector<LongFunction> all = long_functions("sample.cpp", sample_source(kMaxLines), 0);
  ASSERT_EQ(all.size(), 4u);
  EXPECT_EQ(all[0].length, 3);
  EXPECT_EQ(all[2].length, 4);
  EXPECT_EQ(all[3].length, 5);
}

TEST(FunctionLength, NoFunctionInSrcOrRenderIsOverSixtyLines) {
  const fs::path root = KEYFRAME_SOURCE_DIR;
  std::vector<LongFunction> found;
  int files = 0, functions = 0;
  for (const char* dir : {"src", "render"}) {
    ASSERT_TRUE(fs::is_directory(root / dir)) << (root / dir);
    std::vector<fs::path> paths;
    for (const auto& e : fs::recursive_directory_iterator(root / dir))
      if (e.is_regular_file() && (e.path().extension() == ".cpp" || e.path().extension() == ".h"))
        paths.push_back(e.path());
    std::sort(paths.begin(), paths.end());
    for (const fs::path& p : paths) {
      const std::string text = read_text(p), name = fs::relative(p, root).string();
      ++files;
      functions += int(long_functions(name, text, 0).size());
      for (const LongFunction& f : long_functions(name, text, kMaxLines)) found.push_back(f);
    }
  }
  // The scan saw the sources (so an empty result is not an empty scan).
  EXPECT_GT(files, 100);
  EXPECT_GT(functions, 500);
  std::string list;
  for (const LongFunction& f : found)
    list += "\n  " + f.file + ":" + std::to_string(f.line) + " " + std::to_string(f.length) + " lines";
  EXPECT_TRUE(found.empty()) << found.size() << " function bodies over " << kMaxLines
                             << " lines (split each into named steps):" << list;
}

}  // namespace
}  // namespace kf
