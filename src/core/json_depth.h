#pragma once
// A bound on JSON nesting, checked on the text before it is parsed: nlohmann's copies and dump() recurse
// once per level, so 100,000 nested arrays would overflow the stack.
#include <string>
#include <string_view>

namespace kf {

constexpr int kMaxJsonDepth = 256;

// Throws InputError "FILE: line L: JSON nested deeper than 256 levels" when `text` nests arrays and
// objects more than kMaxJsonDepth deep (brackets inside strings do not count).
void check_json_depth(std::string_view text, const std::string& file);

}  // namespace kf
