#include "core/progress.h"

#include <unistd.h>

#include <cstdio>

namespace kf {
namespace {
int g_enabled = -1;  // -1: decide by isatty
bool enabled() {
  if (g_enabled < 0) g_enabled = ::isatty(STDERR_FILENO) ? 1 : 0;
  return g_enabled == 1;
}
}  // namespace

void Progress::set_enabled(bool on) { g_enabled = on ? 1 : 0; }

Progress::Progress(std::string label, long total)
    : label_(std::move(label)), total_(total), active_(enabled()),
      start_(std::chrono::steady_clock::now()), last_(start_) {}

Progress::~Progress() { finish(); }

void Progress::update(long done, const std::string& detail) {
  if (!active_) return;
  auto now = std::chrono::steady_clock::now();
  if (done < total_ && now - last_ < std::chrono::milliseconds(100)) return;
  last_ = now;
  double secs = std::chrono::duration<double>(now - start_).count();
  int pct = total_ > 0 ? int(100.0 * double(done) / double(total_)) : 0;
  std::fprintf(stderr, "\r\033[K%s %3d%% (%ld/%ld) %.1fs %s", label_.c_str(), pct, done, total_, secs,
               detail.c_str());
  std::fflush(stderr);
}

void Progress::finish() {
  if (!active_ || finished_) return;
  finished_ = true;
  std::fprintf(stderr, "\r\033[K");
  std::fflush(stderr);
}

}  // namespace kf
