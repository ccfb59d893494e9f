#pragma once
// Linear air drag proportional to mass, so a finer cloth falls the same way: f_i = -c m_i v_i. Its definite
// D is its exact df/dv and it does not depend on x, so it has no adjoint products.
#include "sim/cloth/cloth_term.h"

namespace kf {

// c: 1/s; m: kg; v: m/s. Force in N.
inline Vec3 air_drag_force(double c, double m, const Vec3& v) { return -c * m * v; }
// d f_i / d v_i = -c m I (N s/m); the force does not depend on x.
inline Mat3 air_drag_jacobian_v(double c, double m) { return -c * m * Mat3::Identity(); }

class AirDragTerm : public ClothTermDefaults {
 public:
  static constexpr ClothStencil kStencil = ClothStencil::kParticle;

  explicit AirDragTerm(const ClothTermSetup& setup) : c_(setup.spec.air_drag) {}
  void add(const ClothState& s, int i, bool /*forces*/, ParticleRow& row) const {
    const double m = s.mass[i];
    row.f += air_drag_force(c_, m, seg(s.v, i));
    row.D += air_drag_jacobian_v(c_, m);
  }

 private:
  double c_;  // 1/s
};

}  // namespace kf
