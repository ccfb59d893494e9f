#include "sim/flock/flock_simd.h"

#include <atomic>

namespace kf {

namespace {
std::atomic<bool> g_allowed{true};

bool processor_has_avx512() {
#ifdef KF_FLOCK_AVX512
  static const bool has = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl");
  return has;
#else
  return false;
#endif
}
}  // namespace

void allow_flock_simd(bool on) { g_allowed = on; }

bool flock_simd_enabled() { return processor_has_avx512() && g_allowed.load(std::memory_order_relaxed); }

}  // namespace kf
