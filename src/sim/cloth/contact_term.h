#pragma once
// Contact with the colliders (collider.h): each particle's pushes from every collider in order, the
// colliders' definite df/dx and df/dv in its row, their energy (those that report it), and the exact
// adjoint's products: each particle's exact df/dx, then each collider's cross couplings (self-contact)
// and the derivative of its definite stiffness.
#include "sim/cloth/cloth_term.h"

namespace kf {

class ContactTerm : public ClothTermDefaults {
 public:
  static constexpr ClothStencil kStencil = ClothStencil::kParticle;
  static constexpr double ClothEnergy::*kEnergy = &ClothEnergy::contact;

  explicit ContactTerm(const ClothTermSetup& setup) : colliders_(&setup.colliders) {}

  // Inline: most sheets have no collider, and their rows then cost nothing here.
  void add(const ClothState& s, int i, bool /*forces*/, ParticleRow& row) const {
    for (const auto& col : *colliders_) {
      ContactForce c;
      if (col->contact(s.n, seg(s.x, i), seg(s.v, i), /*definite=*/true, c)) {
        row.f += c.f;
        row.K += c.dfdx;
        row.D += c.dfdv;
      }
    }
  }
  void add_energy(const ClothState& s, int i, double& e) const {
    for (const auto& col : *colliders_) e += col->energy(s.n, seg(s.x, i));
  }
  void add_adjoint(const ClothAdjoint& a, int i, AdjointRow& row) const {
    for (const auto& col : *colliders_) {
      ContactForce c;
      if (col->contact(a.n, seg(a.x, i), seg(a.v, i), /*definite=*/false, c)) row.x += c.dfdx.transpose() * seg(a.w, i);
    }
  }
  void add_adjoint_coupled(const ClothAdjoint& a, VecX& xhat, VecX& vhat) const;

 private:
  const std::vector<std::unique_ptr<Collider>>* colliders_;
};

}  // namespace kf
