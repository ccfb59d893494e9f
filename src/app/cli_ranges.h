#pragma once
// Command-line values shared by render and farm: image sizes and frame ranges.
#include <string>

namespace kf {

// "WxH" (e.g. 1280x720) into width and height in pixels. Throws InputError naming `option`.
void parse_size(const std::string& text, int& w, int& h, const std::string& option = "--size");

// "A:B" = A..B-1, "A:" = A to the end (end = -1), "A" = A alone. Throws InputError naming `option`.
void parse_frames(const std::string& text, int& begin, int& end, const std::string& option = "--frames");

}  // namespace kf
