#include "app/cli_ranges.h"

#include <regex>

#include "core/error.h"

namespace kf {

void parse_size(const std::string& text, int& w, int& h, const std::string& option) {
  std::smatch m;
  static const std::regex re(R"((\d{1,6})[xX](\d{1,6}))");
  if (!std::regex_match(text, m, re))
    throw InputError(option + ": expected WxH such as 1280x720, got \"" + text + "\"");
  w = std::stoi(m[1]);
  h = std::stoi(m[2]);
  if (w == 0 || h == 0) throw InputError(option + ": expected a non-zero size, got \"" + text + "\"");
}

void parse_frames(const std::string& text, int& begin, int& end, const std::string& option) {
  std::smatch m;
  static const std::regex re(R"((\d{1,7})?(:)?(\d{1,7})?)");
  if (text.empty() || !std::regex_match(text, m, re) || (!m[1].matched && !m[3].matched))
    throw InputError(option + ": expected A:B (" + option.substr(2) + " A..B-1), A: or A, got \"" + text + "\"");
  begin = m[1].matched ? std::stoi(m[1]) : 0;
  end = m[3].matched ? std::stoi(m[3]) : (m[2].matched ? -1 : begin + 1);
}

}  // namespace kf
