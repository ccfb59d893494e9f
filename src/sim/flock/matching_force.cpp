#include "sim/flock/matching_force.h"

#include "sim/flock/smooth_kernel.h"

namespace kf {

Vec3 matching_pair_force(const MatchingParams& p, const Vec3& d, const Vec3& dv) {
  return (p.strength * smooth_kernel(d.squaredNorm(), p.radius).w) * dv;
}

Mat3 matching_pair_dx(const MatchingParams& p, const Vec3& d, const Vec3& dv) {
  const KernelWeight k = smooth_kernel(d.squaredNorm(), p.radius);
  return (2.0 * p.strength * k.dw_dr2) * dv * d.transpose();
}

double matching_pair_dv(const MatchingParams& p, const Vec3& d) {
  return p.strength * smooth_kernel(d.squaredNorm(), p.radius).w;
}

void MatchingForce::add_force(const FlockState& s, int i, Vec3& f) const {
  const Vec3 xi = seg(s.x, i), vi = seg(s.v, i);
  Vec3 fm = Vec3::Zero();
  for (int j : s.neighbors.neighbors(i)) pair_.add_force((xi - seg(s.x, j)).squaredNorm(), vi, seg(s.v, j), fm);
  f += p_.strength * fm;
}

void MatchingForce::sum_KT_DT(const FlockState& s, const VecX& y, int j, Vec3& km, Vec3& dm) const {
  // Column j of K holds d f_j/d x_j = sum_i c (v_i - v_j) g^T and d f_i/d x_j = -c (v_j - v_i) g'^T with
  // g = 2 w' (x_j - x_i) = -g'; together (K^T y)_j = sum_i c g (v_i - v_j)^T (y_j - y_i).
  const Vec3 xj = seg(s.x, j), vj = seg(s.v, j), yj = seg(y, j);
  km.setZero();
  dm.setZero();
  for (int i : s.neighbors.neighbors(j)) {
    const Vec3 d = xj - seg(s.x, i);
    pair_.add_KT_DT(d, d.squaredNorm(), seg(s.v, i), vj, seg(y, i), yj, km, dm);
  }
}

void MatchingForce::add_KT(const FlockState& s, const VecX& y, int j, Vec3& out) const {
  Vec3 km, dm;
  sum_KT_DT(s, y, j, km, dm);
  out += p_.strength * km;
}

void MatchingForce::add_DT(const FlockState& s, const VecX& y, int j, Vec3& out) const {
  Vec3 km, dm;
  sum_KT_DT(s, y, j, km, dm);
  out += p_.strength * dm;
}

}  // namespace kf
