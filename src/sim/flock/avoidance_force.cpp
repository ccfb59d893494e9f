#include "sim/flock/avoidance_force.h"

#include <cmath>

#include "sim/flock/smooth_kernel.h"

namespace kf {

namespace {
constexpr double kSoftening = 0.3;  // eps / R
}

Vec3 avoidance_pair_force(const AvoidanceParams& p, const Vec3& d) {
  const double r2 = d.squaredNorm();
  const KernelWeight k = smooth_kernel(r2, p.radius);
  if (k.w == 0) return Vec3::Zero();
  const double eps = kSoftening * p.radius;
  const double g = 1.0 / std::sqrt(r2 + eps * eps);
  return (p.strength * k.w * g) * d;
}

Mat3 avoidance_pair_jacobian(const AvoidanceParams& p, const Vec3& d) {
  const double r2 = d.squaredNorm();
  const KernelWeight k = smooth_kernel(r2, p.radius);
  if (k.w == 0) return Mat3::Zero();
  const double eps = kSoftening * p.radius;
  const double g = 1.0 / std::sqrt(r2 + eps * eps);
  const double dg_dr2 = -0.5 * g * g * g;
  // f = k w(r2) g(r2) d  =>  df/dd = k [w g I + 2 (w' g + w g') d d^T], ' = d/d(r2).
  return p.strength * (k.w * g * Mat3::Identity() + (2.0 * (k.dw_dr2 * g + k.w * dg_dr2)) * d * d.transpose());
}

void AvoidanceForce::add_force(const FlockState& s, int i, Vec3& f) const {
  const Vec3 xi = seg(s.x, i);
  for (int j : s.neighbors.neighbors(i)) f += avoidance_pair_force(p_, xi - seg(s.x, j));
}

void AvoidanceForce::add_KT(const FlockState& s, const VecX& y, int j, Vec3& out) const {
  // (K^T y)_j = sum_i J(x_j - x_i) (y_j - y_i): J is symmetric and even in d.
  const Vec3 xj = seg(s.x, j), yj = seg(y, j);
  for (int i : s.neighbors.neighbors(j)) out += avoidance_pair_jacobian(p_, xj - seg(s.x, i)) * (yj - seg(y, i));
}

}  // namespace kf
