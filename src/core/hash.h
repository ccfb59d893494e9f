#pragma once
// Hashes: counter-based random numbers (the same inputs give the same numbers on any thread, in any order) and
// the checksum keyframe's own binary files carry.
#include <cstddef>
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

// FNV-1a, 64 bits, of n bytes: any changed, added or lost byte changes it (short of a deliberate forgery).
inline uint64_t fnv1a(const void* data, std::size_t n) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  uint64_t h = 0xcbf29ce484222325ULL;
  for (std::size_t i = 0; i < n; ++i) {
    h ^= bytes[i];
    h *= 0x100000001b3ULL;
  }
  return h;
}

}  // namespace kf
