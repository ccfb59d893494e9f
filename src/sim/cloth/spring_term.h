#pragma once
// The elastic springs of the cloth (stretch, shear and bend, ClothSprings) with Choi & Ko's buckling
// response (buckling_spring.h). The first spring term: it measures each spring (SpringState) for the
// terms after it and assigns the slot's force and stiffness.
#include "sim/cloth/cloth_term.h"

namespace kf {

class SpringTerm : public ClothTermDefaults {
 public:
  static constexpr ClothStencil kStencil = ClothStencil::kSpring;
  static constexpr double ClothEnergy::*kEnergy = &ClothEnergy::elastic;

  explicit SpringTerm(const ClothTermSetup& setup)
      : springs_(&setup.springs.list), count_(int(setup.springs.list.size())) {}
  int springs() const { return count_; }

  void write(const ClothState& s, int k, bool /*forces*/, SpringState& state, SpringSlot& slot) const {
    spring_force_and_definite_jacobian((*springs_)[k], s.x, slot.f, slot.B, state);
  }
  double energy(const VecX& x, int k) const { return spring_energy((*springs_)[k], x); }
  Vec3 conservative_force(const VecX& x, int k) const { return spring_force((*springs_)[k], x); }
  // Assigns t: B dw (B exact and symmetric) plus, with `derivative`, hs d/dd[dw . B_definite dc].
  void spring_adjoint(const ClothAdjoint& a, int k, const SpringState& state, const Vec3& dw, bool derivative,
                      Vec3& t) const {
    const BucklingSpring& sp = (*springs_)[k];
    Vec3 dK;
    spring_adjoint_products(sp, state, derivative, dw, seg(a.c, sp.b) - seg(a.c, sp.a), t, dK);
    if (derivative) t += a.hs * dK;
  }

 private:
  const std::vector<BucklingSpring>* springs_;
  int count_;
};

}  // namespace kf
