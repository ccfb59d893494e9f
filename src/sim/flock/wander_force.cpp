#include "sim/flock/wander_force.h"

#include <cmath>
#include <cstdint>

#include "core/hash.h"

namespace kf {

namespace {

// Uniform in [-1, 1] from (seed, agent, knot, component).
double knot_value(unsigned seed, int agent, int64_t knot, int component) {
  const uint64_t h = mix64(mix64(mix64(uint64_t(seed)) ^ uint64_t(uint32_t(agent))) ^ (uint64_t(knot) * 2 + component));
  return double(h >> 11) * (2.0 / 9007199254740992.0) - 1.0;
}

constexpr size_t kMaxTableEntries = size_t(1) << 24;  // 128 MB of doubles

}  // namespace

Vec3 wander_value(const WanderParams& p, int agent, int n) {
  const double t = n * p.step_ratio / p.correlation_steps;
  const double k = std::floor(t);
  const double a = t - k, s = a * a * (3.0 - 2.0 * a);
  const int64_t knot = int64_t(k);
  Vec3 f;
  f.x() = (1 - s) * knot_value(p.seed, agent, knot, 0) + s * knot_value(p.seed, agent, knot + 1, 0);
  f.y() = 0;
  f.z() = (1 - s) * knot_value(p.seed, agent, knot, 1) + s * knot_value(p.seed, agent, knot + 1, 1);
  return p.strength * f;
}

WanderForce::WanderForce(WanderParams p, int agents, int steps) : p_(p), agents_(agents), tabulated_steps_(0) {
  if (steps > 0 && size_t(steps) * size_t(agents) * 2 <= kMaxTableEntries) tabulated_steps_ = steps;
  table_.resize(size_t(tabulated_steps_) * agents * 2);
  for (int n = 0; n < tabulated_steps_; ++n)
    for (int i = 0; i < agents; ++i) {
      const Vec3 f = wander_value(p_, i, n);
      table_[(size_t(n) * agents + i) * 2] = f.x();
      table_[(size_t(n) * agents + i) * 2 + 1] = f.z();
    }
}

void WanderForce::add_force(const FlockState& s, int i, Vec3& f) const {
  if (s.step >= 0 && s.step < tabulated_steps_) {
    const double* w = &table_[(size_t(s.step) * agents_ + i) * 2];
    f.x() += w[0];
    f.z() += w[1];
  } else {
    f += wander_value(p_, i, s.step);
  }
}

}  // namespace kf
