#include "adjoint/memory_estimate.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>

namespace kf {

std::size_t MemoryEstimate::bytes(int every) const {
  const std::size_t N = std::size_t(std::max(steps, 0));
  if (every <= 0) return base + (N + 1) * per_state + N * per_record;
  const std::size_t k = std::size_t(every);
  const std::size_t kept = (N + k - 1) / k + 2 + std::size_t(std::max(extra_kept, 0));
  return base + kept * (per_state + per_state / 2) + (k + 3) * per_state + (k + 1) * per_record;
}

MemoryEstimate estimate_rollout_memory(const System& sys, int steps, int extra_kept) {
  MemoryEstimate e;
  e.per_state = 2 * sizeof(double) * std::size_t(sys.dof());
  e.per_record = sys.record_bytes_estimate();
  e.steps = steps;
  e.extra_kept = extra_kept;
  return e;
}

std::size_t optimizer_bytes(std::size_t variables, int lbfgs_memory) {
  return sizeof(double) * variables * std::size_t(2 * std::max(lbfgs_memory, 1) + 12);
}

int checkpoint_spacing_for(const MemoryEstimate& e, std::size_t budget, bool& fits) {
  fits = e.bytes(0) <= budget;
  if (fits || e.steps <= 1) return 0;
  // bytes(k) falls like N/k then rises like k: scan around its minimum at sqrt(N * 1.5 s / (s + r)).
  const double s = double(e.per_state), r = double(e.per_record);
  const int guess = std::max(1, int(std::lround(std::sqrt(double(e.steps) * 1.5 * s / std::max(s + r, 1.0)))));
  int best = guess;
  for (int k = std::max(1, guess / 2); k <= std::min(e.steps, 2 * guess + 1); ++k)
    if (e.bytes(k) < e.bytes(best)) best = k;
  fits = e.bytes(best) <= budget;
  return best;
}

std::size_t physical_memory_bytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? std::size_t(pages) * std::size_t(page) : 0;
}

std::size_t default_memory_budget() {
  const std::size_t phys = physical_memory_bytes();
  return phys ? phys / 2 : std::size_t(8) << 30;
}

std::size_t resident_bytes() {
  std::ifstream statm("/proc/self/statm");  // pages: total, resident, ...
  std::size_t total = 0, resident = 0;
  const long page = sysconf(_SC_PAGE_SIZE);
  if (!(statm >> total >> resident) || page <= 0) return 0;
  return resident * std::size_t(page);
}

}  // namespace kf
