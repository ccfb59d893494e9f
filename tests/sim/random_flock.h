#pragma once
// Seeded test positions for flocks: p agents scattered uniformly over the ground square [-scale, scale]² (y = 0).
#include <random>

#include "core/types.h"

namespace kf {

inline VecX random_planar(int p, double scale, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-scale, scale);
  VecX r = VecX::Zero(3 * p);
  for (int i = 0; i < p; ++i) r[3 * i] = u(rng), r[3 * i + 2] = u(rng);
  return r;
}

}  // namespace kf
