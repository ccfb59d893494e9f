#pragma once
// Cuts an optimize job that runs in this process: after `cpu_seconds` of the process's CPU time (user and
// system, every thread) or `wall_seconds` of wall time, whichever comes first, it raises SIGHUP, which the
// job answers by saving its best point and writing its run directory. On a machine other work loads, a
// job's CPU seconds stay near what it would take alone, where its wall seconds grow with the load; the wall
// limit only keeps a starved job from running on without end. Between jobs the caller ignores SIGHUP, so
// a cut that arrives as a job ends does no harm.
#include <condition_variable>
#include <mutex>
#include <thread>

namespace kf {

// CPU seconds (user and system, every thread) this process has used.
double process_cpu_seconds();

class JobDeadline {
 public:
  JobDeadline(double cpu_seconds, double wall_seconds);
  ~JobDeadline();
  JobDeadline(const JobDeadline&) = delete;
  JobDeadline& operator=(const JobDeadline&) = delete;
  bool fired();

 private:
  void watch(double cpu_seconds, double wall_seconds);
  std::mutex m_;
  std::condition_variable cv_;
  bool done_ = false, fired_ = false;
  double cpu_start_ = 0;
  std::thread timer_;
};

}  // namespace kf
