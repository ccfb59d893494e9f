#include "core/warnings.h"

#include <algorithm>
#include <iostream>
#include <mutex>

namespace kf {
namespace {
std::mutex mutex;
std::vector<std::string>& seen() {
  static std::vector<std::string> s;
  return s;
}
}  // namespace

void warn(const std::string& message) {
  std::lock_guard<std::mutex> lock(mutex);
  auto& s = seen();
  if (std::find(s.begin(), s.end(), message) != s.end()) return;
  s.push_back(message);
  std::cerr << "keyframe: warning: " << message << "\n";
}

std::vector<std::string> warnings_so_far() {
  std::lock_guard<std::mutex> lock(mutex);
  return seen();
}

}  // namespace kf
