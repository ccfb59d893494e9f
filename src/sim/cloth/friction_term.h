#pragma once
// Friction at every contact the cloth has (collider.h: the analytic shapes, a character's body, self-contact):
// each collider's smoothed Coulomb force (sim/cloth/friction.h) with its damping block D (the drag
// coefficient at the step's start, not df/dv) in the particle's row. D depends on x and v and is not df/dv,
// so this term has a velocity adjoint: each particle's share of (df/dx)^T w and (df/dv - D)^T w and, exact,
// the x and v derivatives of w^T D(x, v) dv; a pair collider adds its cross couplings
// (the implicit matrix holds no cross block) and its pairs' derivatives in add_adjoint_coupled.
#include "sim/cloth/cloth_term.h"

namespace kf {

class FrictionTerm : public ClothTermDefaults {
 public:
  static constexpr ClothStencil kStencil = ClothStencil::kParticle;
  static constexpr bool kVelocityAdjoint = true;

  explicit FrictionTerm(const ClothTermSetup& setup) : colliders_(&setup.colliders) {}

  void add(const ClothState& s, int i, bool forces, ParticleRow& row) const;
  void add_adjoint(const ClothAdjoint& a, int i, AdjointRow& row) const;
  void add_adjoint_coupled(const ClothAdjoint& a, VecX& xhat, VecX& vhat) const;

 private:
  const std::vector<std::unique_ptr<Collider>>* colliders_;
};

}  // namespace kf
