#include "sim/cloth/imperfection.h"

#include <random>

namespace kf {

void add_imperfection(VecX& x, const Vec3& normal, double amplitude, uint64_t seed, const std::vector<int>& pinned) {
  if (amplitude == 0) return;
  const int particles = int(x.size() / 3);
  std::vector<char> moves(particles, 1);
  for (int i : pinned)
    if (i >= 0 && i < particles) moves[i] = 0;
  std::mt19937_64 rng(seed);  // its output sequence is fixed by the standard; the mapping below is ours
  for (int i = 0; i < particles; ++i) {
    const double unit = double(rng() >> 11) * 0x1.0p-53;  // [0, 1)
    if (moves[i]) seg(x, i) += amplitude * (2 * unit - 1) * normal;
  }
}

}  // namespace kf
