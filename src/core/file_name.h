#pragma once
// Names that become one path component (a run's name read back from scene_name.txt, a scene file's stem
// that names its run directory) and strings that reach generated shell scripts.
#include <string>
#include <string_view>

namespace kf {

// Empty when `name` is a safe single file name: not empty, not "." or "..", no '/', no control
// characters, at most 255 bytes. Otherwise what is wrong with it, e.g. "contains '/'".
std::string file_name_problem(std::string_view name);

// Whether `s` holds a control character (newline, tab, escape, DEL, ...), which no path keyframe writes
// into a script or a one-line message may hold.
bool has_control_character(std::string_view s);

// `s` with control characters shown as \n, \t or \xNN, for one-line messages.
std::string printable(std::string_view s);

}  // namespace kf
