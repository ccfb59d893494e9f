#include "sim/cloth/contact_term.h"

namespace kf {

void ContactTerm::add_adjoint_coupled(const ClothAdjoint& a, VecX& xhat, VecX& /*vhat*/) const {
  for (const auto& col : *colliders_) {
    col->add_cross_transpose(a.n, a.w, a.hs, xhat);
    if (a.exact) col->add_definite_stiffness_derivative(a.n, a.x, a.w, a.c, a.hs * a.hs, xhat);
  }
}

}  // namespace kf
