#pragma once
// Gravity: f_i = m_i g on every particle. Constant, so its Jacobians and adjoint products are zero; its
// energy -m_i g . x_i is counted on free particles (a pin's is not the cloth's to account for).
#include "sim/cloth/cloth_term.h"

namespace kf {

// m: kg; g: m/s^2. Force in N.
inline Vec3 gravity_force(double m, const Vec3& g) { return m * g; }

class GravityTerm : public ClothTermDefaults {
 public:
  static constexpr ClothStencil kStencil = ClothStencil::kParticle;
  static constexpr double ClothEnergy::*kEnergy = &ClothEnergy::gravity;

  explicit GravityTerm(const ClothTermSetup& setup) : g_(setup.spec.gravity) {}
  void add(const ClothState& s, int i, bool /*forces*/, ParticleRow& row) const {
    row.f += gravity_force(s.mass[i], g_);
  }
  void add_energy(const ClothState& s, int i, double& e) const {
    if (s.free[i]) e -= s.mass[i] * g_.dot(seg(s.x, i));
  }

 private:
  Vec3 g_;  // m/s^2
};

}  // namespace kf
