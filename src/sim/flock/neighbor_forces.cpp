#include "sim/flock/neighbor_forces.h"

#include <algorithm>
#include <cmath>

#include "sim/flock/smooth_kernel.h"

namespace kf {

NeighborForces::NeighborForces(const FlockSpec& s)
    : ka_(s.avoidance.strength),
      kmatch_(s.matching.strength),
      kc_(s.centering.strength),
      avoid_({s.avoidance.strength, s.avoidance.radius}),
      match_({s.matching.strength, s.matching.radius}),
      centre_({s.centering.strength, s.centering.radius}) {
  if (ka_ > 0) radius_ = std::max(radius_, s.avoidance.radius);
  if (kmatch_ > 0) radius_ = std::max(radius_, s.matching.radius);
  if (kc_ > 0) radius_ = std::max(radius_, s.centering.radius);
}

Vec3 NeighborForces::force(const VecX& x, const VecX& v, std::span<const int> nbrs, int i, Vec3& offset_i,
                           double& b_i) const {
  const Vec3 xi = seg(x, i), vi = seg(v, i);
  Vec3 fa = Vec3::Zero(), fm = Vec3::Zero(), a = Vec3::Zero();
  double b = 1.0;
  for (int j : nbrs) {
    const Vec3 d = xi - seg(x, j);
    const double r2 = d.squaredNorm();
    avoid_.add_force(d, r2, fa);
    match_.add_force(r2, vi, seg(v, j), fm);
    centre_.add_sums(d, r2, a, b);
  }
  offset_i = a / b;
  b_i = b;
  return ka_ * fa + kmatch_ * fm + kc_ * offset_i;
}

void NeighborForces::centering(const VecX& x, std::span<const int> nbrs, int i, Vec3& offset_i, double& b_i) const {
  const Vec3 xi = seg(x, i);
  Vec3 a = Vec3::Zero();
  double b = 1.0;
  for (int j : nbrs) {
    const Vec3 d = xi - seg(x, j);
    centre_.add_sums(d, d.squaredNorm(), a, b);
  }
  offset_i = a / b;
  b_i = b;
}

void NeighborForces::transpose_apply(const VecX& x, const VecX& v, const VecX& y, std::span<const int> nbrs, int j,
                                     const VecX& offset, const std::vector<double>& b, Vec3& kt, Vec3& dt) const {
  const Vec3 xj = seg(x, j), vj = seg(v, j), yj = seg(y, j), oj = seg(offset, j);
  const double cj = kc_ / b[j];
  Vec3 ka = Vec3::Zero(), km = Vec3::Zero(), kc = Vec3::Zero(), dm = Vec3::Zero();
  for (int i : nbrs) {
    const Vec3 d = xj - seg(x, i);  // x_j - x_i
    const double r2 = d.squaredNorm();
    const Vec3 yi = seg(y, i);
    avoid_.add_KT(d, r2, yj - yi, ka);
    match_.add_KT_DT(d, r2, seg(v, i), vj, yi, yj, km, dm);
    centre_.add_KT(d, r2, yi, yj, seg(offset, i), oj, b[i], cj, kc);
  }
  kt += ka_ * ka + kmatch_ * km + kc;
  dt += kmatch_ * dm;
}

}  // namespace kf
