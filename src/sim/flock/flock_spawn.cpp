#include "sim/flock/flock_spawn.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "core/hash.h"

namespace kf {

VecX spawn_positions(const FlockSpec& spec, unsigned seed) {
  const int p = spec.agents;
  const double dmin = spec.min_spawn_distance(), R = spec.spawn.radius;
  // Coarsest lattice whose points, shrunk in by the jitter, still number p.
  double s = std::max(dmin, std::sqrt(M_PI * R * R / p)), jitter = 0;
  for (;;) {
    jitter = 0.5 * (s - dmin);
    if (lattice_points_in_disc(s, R - jitter, p) >= p) break;
    s *= 0.99;
    if (s <= dmin) {
      s = dmin;
      jitter = 0;
      break;
    }
  }
  const double inner = R - jitter;
  const long n = long(std::floor(std::max(inner, 0.0) / s));
  std::vector<std::tuple<long, long, long>> points;  // (|lattice|^2, a, c)
  for (long a = -n; a <= n; ++a)
    for (long c = -n; c <= n; ++c)
      if (double(a * a + c * c) * s * s <= inner * inner) points.emplace_back(a * a + c * c, a, c);
  std::sort(points.begin(), points.end());
  // The parser refuses such a disc; a spec built in code must not stack the surplus agents on one point.
  if (long(points.size()) < long(p))
    throw std::invalid_argument("spawn_positions: a disc of radius " + std::to_string(R) + " m holds " +
                                std::to_string(points.size()) + " of " + std::to_string(p) + " agents");

  VecX x = VecX::Zero(3 * p);
  for (int i = 0; i < p; ++i) {
    const auto [r2, a, c] = points[i];
    const uint64_t h = mix64(mix64(uint64_t(seed) ^ 0x5F1A7E5EEDULL) ^ uint64_t(i));
    const double angle = 2 * M_PI * unit_double(h), rho = jitter * std::sqrt(unit_double(mix64(h)));
    seg(x, i) = spec.spawn.center + Vec3(a * s + rho * std::cos(angle), 0.0, c * s + rho * std::sin(angle));
    x[3 * i + 1] = 0.0;
  }
  return x;
}

}  // namespace kf
