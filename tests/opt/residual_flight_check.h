#pragma once
// The residual Jacobian's transpose (one adjoint pass, ResidualFlight::transpose_times) against central
// differences of w·r(z + h d) at two step sizes, for the tests of Gauss–Newton onto the keyframes.
#include <gtest/gtest.h>

#include "core/types.h"
#include "opt/keyframe_residuals.h"

namespace kf::test {

struct ResidualDirectional {
  bool ok = false;               // the flight at z and its adjoint pass both succeeded
  double analytic = 0;           // (Jᵀw)·d
  double coarse = 0, fine = 0;   // central differences of w·r along d at the two steps
};

inline ResidualDirectional residual_directional(ResidualFlight& flight, const VecX& z, const VecX& w, const VecX& d,
                                               double coarse_step, double fine_step) {
  ResidualDirectional out;
  VecX g;
  if (!flight.fly(z) || !flight.transpose_times(w, g)) return out;
  out.ok = true;
  out.analytic = g.dot(d);
  const auto central = [&](double h) {
    EXPECT_TRUE(flight.fly(z + h * d));
    const double plus = w.dot(flight.residuals());
    EXPECT_TRUE(flight.fly(z - h * d));
    return (plus - w.dot(flight.residuals())) / (2 * h);
  };
  out.coarse = central(coarse_step);
  out.fine = central(fine_step);
  return out;
}

}  // namespace kf::test
