#include "bench/job_deadline.h"

#include <sys/resource.h>

#include <chrono>
#include <csignal>

namespace kf {

double process_cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

JobDeadline::JobDeadline(double cpu_seconds, double wall_seconds)
    : cpu_start_(process_cpu_seconds()), timer_([this, cpu_seconds, wall_seconds] { watch(cpu_seconds, wall_seconds); }) {}

JobDeadline::~JobDeadline() {
  {
    std::lock_guard<std::mutex> lock(m_);
    done_ = true;
  }
  cv_.notify_all();
  timer_.join();
}

bool JobDeadline::fired() {
  std::lock_guard<std::mutex> lock(m_);
  return fired_;
}

// Looks at the clocks a few times a second: CPU time has no timer to wait on.
void JobDeadline::watch(double cpu_seconds, double wall_seconds) {
  const auto start = std::chrono::steady_clock::now();
  const auto wall_end = start + std::chrono::duration<double>(wall_seconds);
  std::unique_lock<std::mutex> lock(m_);
  while (!done_) {
    const auto now = std::chrono::steady_clock::now();
    if (now >= wall_end || process_cpu_seconds() - cpu_start_ >= cpu_seconds) {
      fired_ = true;
      std::raise(SIGHUP);
      return;
    }
    cv_.wait_for(lock, std::min<std::chrono::steady_clock::duration>(
                           std::chrono::milliseconds(200),
                           std::chrono::duration_cast<std::chrono::steady_clock::duration>(wall_end - now)));
  }
}

}  // namespace kf
