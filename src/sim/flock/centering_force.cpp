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
    const Vec3 xi = seg(s.x, i);
    Vec3 a = Vec3::Zero();
    double b = 1.0;
    for (int j : s.neighbors.neighbors(i)) {
      const Vec3 d = xi - seg(s.x, j);
      pair_.add_sums(d, d.squaredNorm(), a, b);
    }
    seg(offset_, i) = a / b;
    b_[i] = b;
  });
}

void CenteringForce::add_force(const FlockState& s, int i, Vec3& f) const { f += p_.strength * seg(offset_, i); }

void CenteringForce::add_KT(const FlockState& s, const VecX& y, int j, Vec3& out) const {
  const Vec3 xj = seg(s.x, j), yj = seg(y, j), oj = seg(offset_, j);
  const double cj = p_.strength / b_[j];
  Vec3 kc = Vec3::Zero();
  for (int i : s.neighbors.neighbors(j)) {
    const Vec3 d = xj - seg(s.x, i);
    pair_.add_KT(d, d.squaredNorm(), seg(y, i), yj, seg(offset_, i), oj, b_[i], cj, kc);
  }
  out += kc;
}

}  // namespace kf
