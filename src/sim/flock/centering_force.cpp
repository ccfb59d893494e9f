#include "sim/flock/centering_force.h"

#include "sim/flock/parallel_agents.h"
#include "sim/flock/smooth_kernel.h"

namespace kf {

void CenteringForce::prepare(const FlockState& s) {
  const int p = int(s.x.size() / 3);
  if (offset_.size() != s.x.size()) {
    offset_.resize(s.x.size());
    b_.resize(p);
  }
  parallel_agents(p, [&](int i) {
    {
      const Vec3 xi = seg(s.x, i);
      Vec3 a = Vec3::Zero();
      double b = 1.0;
      for (int j : s.neighbors.neighbors(i)) {
        const Vec3 e = seg(s.x, j) - xi;
        const double w = smooth_kernel(e.squaredNorm(), p_.radius).w;
        a += w * e;
        b += w;
      }
      seg(offset_, i) = a / b;
      b_[i] = b;
    }
  });
}

void CenteringForce::add_force(const FlockState& s, int i, Vec3& f) const { f += p_.strength * seg(offset_, i); }

Vec3 CenteringForce::block_T_times(const FlockState& s, int i, int j, const Vec3& y3) const {
  const Vec3 d = seg(s.x, i) - seg(s.x, j);
  const KernelWeight k = smooth_kernel(d.squaredNorm(), p_.radius);
  const Vec3 g = 2.0 * k.dw_dr2 * d;  // d w_ij / d x_i
  return (p_.strength / b_[i]) * (k.w * y3 + (d + seg(offset_, i)).dot(y3) * g);
}

void CenteringForce::add_KT(const FlockState& s, const VecX& y, int j, Vec3& out) const {
  // (K^T y)_j = (d f_j/d x_j)^T y_j + sum_i (d f_i/d x_j)^T y_i, and d f_j/d x_j = -sum_i d f_j/d x_i
  // (translation invariance).
  const Vec3 yj = seg(y, j);
  for (int i : s.neighbors.neighbors(j)) out += block_T_times(s, i, j, seg(y, i)) - block_T_times(s, j, i, yj);
}

}  // namespace kf
