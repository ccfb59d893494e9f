#pragma once
// Counter-based random numbers: the same inputs give the same numbers on any thread, in any order.
#include <cstdint>

namespace kf {

// SplitMix64's finaliser: a well-mixed 64-bit hash of z.
inline uint64_t mix64(uint64_t z) {
  z += 0x9E3779B97F4A7C15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// The top 53 bits of h as a double in [0, 1).
inline double unit_double(uint64_t h) { return double(h >> 11) / 9007199254740992.0; }

}  // namespace kf
