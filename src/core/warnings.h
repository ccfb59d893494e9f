#pragma once
// Warnings: something in the input is allowed but probably not what the user meant (a cape whose pinned
// edge jumps to its anchors, a keyframe the particles cannot reach). Each is printed once per process as
// "keyframe: warning: MESSAGE" on stderr, however often the scene is loaded or its system built.
#include <string>
#include <vector>

namespace kf {

void warn(const std::string& message);
// Every distinct warning so far, in order (tests).
std::vector<std::string> warnings_so_far();

}  // namespace kf
