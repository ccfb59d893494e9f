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
  for (int j : s.neighbors.neighbors(i)) f += matching_pair_force(p_, xi - seg(s.x, j), seg(s.v, j) - vi);
}

void MatchingForce::add_KT(const FlockState& s, const VecX& y, int j, Vec3& out) const {
  // Column j of K holds d f_j/d x_j = sum_i c (v_i - v_j) g^T and d f_i/d x_j = -c (v_j - v_i) g'^T with
  // g = 2 w' (x_j - x_i) = -g'; together (K^T y)_j = sum_i c g (v_i - v_j)^T (y_j - y_i).
  const Vec3 xj = seg(s.x, j), vj = seg(s.v, j), yj = seg(y, j);
  for (int i : s.neighbors.neighbors(j)) {
    const Vec3 d = xj - seg(s.x, i);
    const KernelWeight k = smooth_kernel(d.squaredNorm(), p_.radius);
    out += (2.0 * p_.strength * k.dw_dr2 * (seg(s.v, i) - vj).dot(yj - seg(y, i))) * d;
  }
}

void MatchingForce::add_DT(const FlockState& s, const VecX& y, int j, Vec3& out) const {
  const Vec3 xj = seg(s.x, j), yj = seg(y, j);
  for (int i : s.neighbors.neighbors(j)) out += matching_pair_dv(p_, xj - seg(s.x, i)) * (seg(y, i) - yj);
}

}  // namespace kf
