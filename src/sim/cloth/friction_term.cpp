#include "sim/cloth/friction_term.h"

namespace kf {

void FrictionTerm::add(const ClothState& s, int i, bool /*forces*/, ParticleRow& row) const {
  ContactForce c;
  for (const auto& col : *colliders_)
    if (col->friction(s.n, seg(s.x, i), seg(s.v, i), /*exact=*/false, c)) {
      row.f += c.f;
      row.D += c.dfdv;
    }
}

void FrictionTerm::add_adjoint(const ClothAdjoint& a, int i, AdjointRow& row) const {
  ContactForce c;
  for (const auto& col : *colliders_) {
    if (!col->friction(a.n, seg(a.x, i), seg(a.v, i), /*exact=*/true, c)) continue;
    row.x += c.dfdx.transpose() * seg(a.w, i);
    row.v += c.dfdv_rest.transpose() * seg(a.w, i);
    if (!a.exact) continue;
    Vec3 ddx, ddv;
    col->damping_derivative(a.n, seg(a.x, i), seg(a.v, i), seg(a.w, i), seg(a.dv, i), ddx, ddv);
    row.x += ddx;
    row.v += ddv;
  }
}

void FrictionTerm::add_adjoint_coupled(const ClothAdjoint& a, VecX& xhat, VecX& vhat) const {
  for (const auto& col : *colliders_) col->add_friction_coupled(a.n, a.w, a.dv, a.hs, a.exact, xhat, vhat);
}

}  // namespace kf
