#pragma once
// Damping along the type-1 springs (structural and shear, spring_damping.h): resists the rate at which a
// spring's ends separate. Its Bd = c n n^T is its exact df/dv and depends on x only; the step's matrix
// leaves its x-derivative out (kept symmetric), the adjoint puts it back.
#include "sim/cloth/cloth_term.h"
#include "sim/cloth/spring_damping.h"

namespace kf {

class SpringDampingTerm : public ClothTermDefaults {
 public:
  static constexpr ClothStencil kStencil = ClothStencil::kSpring;
  static constexpr bool kDampingSlot = true;

  explicit SpringDampingTerm(const ClothTermSetup& setup)
      : springs_(&setup.springs.list), damped_(setup.springs.damped), c_(setup.spec.damping) {}
  int springs() const { return damped_; }

  void write(const ClothState& s, int k, bool forces, SpringState& state, SpringSlot& slot) const {
    const BucklingSpring& sp = (*springs_)[k];
    if (forces) slot.f += damping_force(sp, c_, state, s.v);
    slot.Bd = damping_jacobian_v(sp, c_, state);
  }
  // Adds (d f_a / d x_b)^T dw and, with `derivative`, d/dd[dw . Bd ddv] (ddv = dv_b - dv_a).
  void spring_adjoint(const ClothAdjoint& a, int k, const SpringState& state, const Vec3& dw, bool derivative,
                      Vec3& t) const {
    const BucklingSpring& sp = (*springs_)[k];
    t += damping_adjoint_products(sp, c_, state, a.v, dw, derivative, seg(a.dv, sp.b) - seg(a.dv, sp.a));
  }

 private:
  const std::vector<BucklingSpring>* springs_;
  int damped_;
  double c_;  // N s/m
};

}  // namespace kf
