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

// The same two at the positions `state` came from (the step's assembly, which has the spring's direction).
Vec3 damping_force(const BucklingSpring& sp, double c, const SpringState& state, const VecX& v);
Mat3 damping_jacobian_v(const BucklingSpring& sp, double c, const SpringState& state);

// d(force on a)/d(x_b) (3x3, N/m, not symmetric); d/d(x_a) is its negative. The implicit matrix leaves
// it out (as Baraff & Witkin do, keeping the matrix symmetric); the adjoints use it in their exact df/dx.
Mat3 damping_jacobian_x(const BucklingSpring& sp, double c, const VecX& x, const VecX& v);

// d/dd [p . (c n n^T) q], d = x_b - x_a: the position derivative of damping_jacobian_v met by p and q.
Vec3 damping_jacobian_v_derivative(const BucklingSpring& sp, double c, const VecX& x, const Vec3& p, const Vec3& q);

// What the exact adjoint needs of the damping at the positions `state` came from, without forming a matrix:
// damping_jacobian_x(sp, c, x, v)^T p, plus damping_jacobian_v_derivative(sp, c, x, p, q) when `derivative`
// is true; equal to those to round-off.
Vec3 damping_adjoint_products(const BucklingSpring& sp, double c, const SpringState& state, const VecX& v,
                              const Vec3& p, bool derivative, const Vec3& q);

}  // namespace kf
