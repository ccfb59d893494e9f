#include "sim/flock/avoidance_force.h"

#include <cmath>

#include "sim/flock/smooth_kernel.h"

namespace kf {

namespace {
// The pair's kernel weight and softened inverse distance g = (r2 + eps^2)^-1/2 at d = x_i - x_j.
KernelWeight softened(const AvoidanceParams& p, const Vec3& d, double& r2, double& g) {
  r2 = d.squaredNorm();
  const double eps = AvoidancePair::kSoftening * p.radius;
  g = 1.0 / std::sqrt(r2 + eps * eps);
  return smooth_kernel(r2, p.radius);
}
}  // namespace

Vec3 avoidance_pair_force(const AvoidanceParams& p, const Vec3& d) {
  double r2, g;
  const KernelWeight k = softened(p, d, r2, g);
  if (k.w == 0) return Vec3::Zero();
  return (p.strength * k.w * g) * d;
}

Mat3 avoidance_pair_jacobian(const AvoidanceParams& p, const Vec3& d) {
  double r2, g;
  const KernelWeight k = softened(p, d, r2, g);
  if (k.w == 0) return Mat3::Zero();
  const double dg_dr2 = -0.5 * g * g * g;
  // f = k w(r2) g(r2) d  =>  df/dd = k [w g I + 2 (w' g + w g') d d^T], ' = d/d(r2).
  return p.strength * (k.w * g * Mat3::Identity() + (2.0 * (k.dw_dr2 * g + k.w * dg_dr2)) * d * d.transpose());
}

void AvoidanceForce::add_force(const FlockState& s, int i, Vec3& f) const {
  const Vec3 xi = seg(s.x, i);
  Vec3 fa = Vec3::Zero();
  for (int j : s.neighbors.neighbors(i)) {
    const Vec3 d = xi - seg(s.x, j);
    pair_.add_force(d, d.squaredNorm(), fa);
  }
  f += p_.strength * fa;
}

void AvoidanceForce::add_KT(const FlockState& s, const VecX& y, int j, Vec3& out) const {
  // (K^T y)_j = sum_i J(x_j - x_i) (y_j - y_i): J is symmetric and even in d.
  const Vec3 xj = seg(s.x, j), yj = seg(y, j);
  Vec3 ka = Vec3::Zero();
  for (int i : s.neighbors.neighbors(j)) {
    const Vec3 d = xj - seg(s.x, i);
    const Vec3 e = yj - seg(y, i);
    pair_.add_KT(d, d.squaredNorm(), e, ka);
  }
  out += p_.strength * ka;
}

}  // namespace kf
