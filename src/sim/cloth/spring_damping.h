#pragma once
// Damping along a spring: resists the rate at which its two ends separate, not rigid motion.
// Force on a: c (n . (v_b - v_a)) n with n = (x_b - x_a)/|x_b - x_a|; on b its negative.
// A spring without a direction (|x_b - x_a| <= 1e-9 L, or exactly 0 when L = 0) is not damped: force and
// Jacobians 0.
#include "core/types.h"
#include "sim/cloth/buckling_spring.h"

namespace kf {

// Force on particle a (N). c: N s/m. x, v: 3p (m, m/s).
Vec3 damping_force(const BucklingSpring& sp, double c, const VecX& x, const VecX& v);

// d(force on a)/d(v_b) = c n n^T (3x3, N s/m, symmetric); d/d(v_a) is its negative.
Mat3 damping_jacobian_v(const BucklingSpring& sp, double c, const VecX& x);

// d(force on a)/d(x_b) (3x3, N/m, not symmetric); d/d(x_a) is its negative. The cloth system leaves this
// out of K in both the forward and the adjoint pass (as Baraff & Witkin do); it is here for completeness.
Mat3 damping_jacobian_x(const BucklingSpring& sp, double c, const VecX& x, const VecX& v);

}  // namespace kf
