#include "sim/flock/neighbor_forces.h"

#include <algorithm>
#include <cmath>

#include "sim/flock/smooth_kernel.h"

namespace kf {

namespace {
constexpr double kAvoidanceSoftening = 0.3;  // eps / R, as in avoidance_force.cpp

// The shared kernel (smooth_kernel.h) in the fused loop's calling convention.
inline void kernel(double r2, double inv_R2, double& w, double& dw) {
  const KernelWeight k = smooth_kernel(r2, 1.0 / std::sqrt(inv_R2));
  w = k.w;
  dw = k.dw_dr2;
}
}  // namespace

NeighborForces::NeighborForces(const FlockSpec& s)
    : ka_(s.avoidance.strength), ra2_(s.avoidance.radius * s.avoidance.radius), kmatch_(s.matching.strength),
      rm2_(s.matching.radius * s.matching.radius), kc_(s.centering.strength),
      rc2_(s.centering.radius * s.centering.radius) {
  inv_ra2_ = 1.0 / ra2_;
  inv_rm2_ = 1.0 / rm2_;
  inv_rc2_ = 1.0 / rc2_;
  eps2_ = kAvoidanceSoftening * kAvoidanceSoftening * ra2_;
  if (ka_ > 0) radius_ = std::max(radius_, s.avoidance.radius);
  if (kmatch_ > 0) radius_ = std::max(radius_, s.matching.radius);
  if (kc_ > 0) radius_ = std::max(radius_, s.centering.radius);
  // A switched-off term must never contribute, whatever its radius.
  if (ka_ == 0) ra2_ = 0;
  if (kmatch_ == 0) rm2_ = 0;
  if (kc_ == 0) rc2_ = 0;
}

Vec3 NeighborForces::force(const VecX& x, const VecX& v, std::span<const int> nbrs, int i, Vec3& offset_i,
                           double& b_i) const {
  const Vec3 xi = seg(x, i), vi = seg(v, i);
  Vec3 fa = Vec3::Zero(), fm = Vec3::Zero(), a = Vec3::Zero();
  double b = 1.0, w, dw;
  for (int j : nbrs) {
    const Vec3 d = xi - seg(x, j);
    const double r2 = d.squaredNorm();
    if (r2 < ra2_) {
      kernel(r2, inv_ra2_, w, dw);
      fa += (w / std::sqrt(r2 + eps2_)) * d;
    }
    if (r2 < rm2_) {
      kernel(r2, inv_rm2_, w, dw);
      fm += w * (seg(v, j) - vi);
    }
    if (r2 < rc2_) {
      kernel(r2, inv_rc2_, w, dw);
      a -= w * d;
      b += w;
    }
  }
  offset_i = a / b;
  b_i = b;
  return ka_ * fa + kmatch_ * fm + kc_ * offset_i;
}

void NeighborForces::centering(const VecX& x, std::span<const int> nbrs, int i, Vec3& offset_i, double& b_i) const {
  const Vec3 xi = seg(x, i);
  Vec3 a = Vec3::Zero();
  double b = 1.0, w, dw;
  for (int j : nbrs) {
    const Vec3 d = xi - seg(x, j);
    const double r2 = d.squaredNorm();
    if (r2 < rc2_) {
      kernel(r2, inv_rc2_, w, dw);
      a -= w * d;
      b += w;
    }
  }
  offset_i = a / b;
  b_i = b;
}

void NeighborForces::transpose_apply(const VecX& x, const VecX& v, const VecX& y, std::span<const int> nbrs, int j,
                                     const VecX& offset, const std::vector<double>& b, Vec3& kt, Vec3& dt) const {
  const Vec3 xj = seg(x, j), vj = seg(v, j), yj = seg(y, j), oj = seg(offset, j);
  const double cj = kc_ / b[j];
  Vec3 ka = Vec3::Zero(), km = Vec3::Zero(), kc = Vec3::Zero(), dm = Vec3::Zero();
  double w, dw;
  for (int i : nbrs) {
    const Vec3 d = xj - seg(x, i);  // x_j - x_i
    const double r2 = d.squaredNorm();
    const Vec3 yi = seg(y, i);
    if (r2 < ra2_) {
      // J(d)(y_j - y_i), J = w g I + 2 (w' g + w g') d d^T with g = (r2 + eps^2)^-1/2: symmetric, even in d.
      kernel(r2, inv_ra2_, w, dw);
      const double g = 1.0 / std::sqrt(r2 + eps2_);
      const Vec3 e = yj - yi;
      ka += (w * g) * e + (2.0 * (dw * g - 0.5 * w * g * g * g) * d.dot(e)) * d;
    }
    if (r2 < rm2_) {
      kernel(r2, inv_rm2_, w, dw);
      km += (2.0 * dw * (seg(v, i) - vj).dot(yj - yi)) * d;
      dm += w * (yi - yj);
    }
    if (r2 < rc2_) {
      // (d f_i/d x_j)^T y_i - (d f_j/d x_i)^T y_j; block (c/b_i)[w y + ((x_i - x_j) + offset_i).y g_i],
      // g_i = 2 w' (x_i - x_j) = -2 w' d.
      kernel(r2, inv_rc2_, w, dw);
      const Vec3 gi = -2.0 * dw * d;
      const Vec3 from_i = (kc_ / b[i]) * (w * yi + (seg(offset, i) - d).dot(yi) * gi);
      const Vec3 from_j = cj * (w * yj - (d + oj).dot(yj) * gi);
      kc += from_i - from_j;
    }
  }
  kt += ka_ * ka + kmatch_ * km + kc;
  dt += kmatch_ * dm;
}

}  // namespace kf
