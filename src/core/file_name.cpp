#include "core/file_name.h"

#include <cstdio>

namespace kf {

bool has_control_character(std::string_view s) {
  for (unsigned char c : s)
    if (c < 0x20 || c == 0x7f) return true;
  return false;
}

std::string file_name_problem(std::string_view name) {
  if (name.empty()) return "is empty";
  if (name == "." || name == "..") return "is \"" + std::string(name) + "\"";
  if (name.find('/') != std::string_view::npos) return "contains '/'";
  if (has_control_character(name)) return "contains a control character";
  if (name.size() > 255) return "is longer than 255 bytes";
  return {};
}

std::string printable(std::string_view s) {
  std::string out;
  for (unsigned char c : s) {
    if (c == '\n') out += "\\n";
    else if (c == '\t') out += "\\t";
    else if (c < 0x20 || c == 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      out += hex;
    } else {
      out += char(c);
    }
  }
  return out;
}

}  // namespace kf
