#pragma once
// The C2 weight shared by the neighbour forces: w(r) = (1 - r^2/R^2)^3 for r < R, else 0.
// Value, slope and curvature vanish at r = R, so forces and their Jacobians are continuous at the
// cut-off and the Jacobians have no kink there either (finite-difference checks stay at round-off).

#include <cmath>

namespace kf {

struct KernelWeight {
  double w = 0;       // weight, dimensionless, in [0, 1]
  double dw_dr2 = 0;  // derivative with respect to r^2 (1/m^2); d w/d x_i = 2 dw_dr2 (x_i - x_j)
};

// r2: squared distance (m^2); inv_radius2: 1/R^2 for the cut-off R (m), what the neighbour loop keeps per
// term, so a pair costs no square root or division.
inline KernelWeight smooth_kernel_inv(double r2, double inv_radius2) {
  const double t = 1.0 - r2 * inv_radius2;
  if (t <= 0) return {};
  return {t * t * t, -3.0 * t * t * inv_radius2};
}

// The same from R (m).
inline KernelWeight smooth_kernel(double r2, double radius) { return smooth_kernel_inv(r2, 1.0 / (radius * radius)); }

}  // namespace kf
