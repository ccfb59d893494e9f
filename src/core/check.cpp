#include "core/check.h"

#include <cstdio>
#include <cstdlib>

#include "core/error.h"

namespace kf::detail {

void check_failed(const char* file, int line, const std::string& what, const std::string& values) {
  std::fflush(stdout);
  std::fprintf(stderr, "keyframe: internal error: %s:%d: %s failed%s%s\n", file, line, what.c_str(),
               values.empty() ? "" : ": ", values.c_str());
  std::fflush(stderr);
  std::_Exit(kExitInternal);
}

}  // namespace kf::detail
