#pragma once
// Choi & Ko (2002) springs: linear in tension, a buckling response in compression.
//
// A spring between particles a and b with rest length L carries a tension T(s) along d = x_b - x_a,
// s = |d|: the force on a is T d/s, on b its opposite. In tension (s >= L) T = k (s - L). In compression a
// cloth strip does not resist like a rod: it buckles. After Choi & Ko the compressive force rises to about
// the Euler buckling load F_b and then grows only slowly (post-buckling stiffness k_p):
//     T(s) = -( F_b (1 - exp(-(k - k_p) e / F_b)) + k_p e ),   e = L - s > 0.
// That law meets the linear one at s = L with the same slope but not the same curvature, and the step's
// matrix holds the slope: every spring crossing its rest length would put a kink into the step map. So for
// e below e0 = kBuckleBlend F_b / (k - k_p) the linear law -k e blends into Choi-Ko's with a quintic
// smoothstep, which makes T C2 in s (force, stiffness and its slope continuous everywhere).
// Type-1 springs (structural, shear) and type-2 springs (bending: across two edges) share this law with
// their own k; F_b = k L buckle_strain and k_p = buckle_stiffness k.
#include "core/types.h"

namespace kf {

// The compression over which the linear law blends into the buckling response, as a fraction of the
// response's own length scale F_b / (k - k_p).
inline constexpr double kBuckleBlend = 0.5;

// The definite Jacobian fades the transverse stiffness in over strains 0 .. transverse_ramp (see
// spring_jacobian); this is its default (the scene key cloth.transverse_ramp).
inline constexpr double kTransverseRamp = 0.05;

struct BucklingSpring {
  int a = 0, b = 0;          // particle indices
  double rest = 1.0;         // L, metres
  double k = 0.0;            // tension stiffness, N/m
  double k_post = 0.0;       // post-buckling stiffness k_p <= k, N/m
  double f_buckle = 0.0;     // buckling load F_b > 0, N (0: linear in compression too)
  double transverse_ramp = kTransverseRamp;  // strain over which the definite transverse stiffness fades in
};

// Tension T (N, positive pulls the ends together), its slope dT/ds (N/m, always >= 0) and curvature
// d2T/ds2 (N/m^2) at length s.
void spring_tension(const BucklingSpring& sp, double s, double& T, double& dT_ds, double& d2T_ds2);

// Stored energy (J) at length s = |x_b - x_a|: the integral of T from L to s, >= 0 and 0 only at s = L.
// Tension: k (s - L)^2 / 2; compression: by quadrature over the blend, in closed form beyond.
// A zero-rest-length spring stores k |d|^2 / 2. x: 3p positions, metres.
double spring_energy(const BucklingSpring& sp, const VecX& x);

// Force on particle a (N); the force on b is its negative. x: 3p positions, metres.
Vec3 spring_force(const BucklingSpring& sp, const VecX& x);

// B = d(force on a)/d(x_b) (3x3, N/m). The spring's 6x6 stiffness is [[-B, B], [B, -B]] (B symmetric).
// `definite` keeps the transverse term T/s only in tension, faded in smoothly over strains
// 0 .. sp.transverse_ramp (never negative, so -K is positive semi-definite and the implicit matrix SPD;
// C1, so the step map has no kink where a spring passes its rest length); the exact Jacobian is
// definite = false.
// Springs shorter than 1e-9 L (L > 0) have no direction: force 0 and B = dT/ds I (finite, never NaN).
// A zero-rest-length spring (L = 0) is the linear spring f_a = k d with B = k I at every length, s = 0
// included: its axial and transverse stiffnesses are both k, so the direction never enters.
Mat3 spring_jacobian(const BucklingSpring& sp, const VecX& x, bool definite);

// A spring's length s = |x_b - x_a|, direction n (0 when s = 0) and tension with its first two derivatives
// at s, as the step's assembly finds them: what the adjoint's products at the same positions reuse.
struct SpringState {
  Vec3 n = Vec3::Zero();
  double s = 0, T = 0, dT = 0, d2T = 0;
};

// spring_force and spring_jacobian(definite = true) from one evaluation of the tension (the step's
// assembly needs both), equal to them bit for bit; `state` receives what they were computed from.
void spring_force_and_definite_jacobian(const BucklingSpring& sp, const VecX& x, Vec3& f, Mat3& B,
                                        SpringState& state);

// d/dd [p . B(d) q] with d = x_b - x_a (N/m^2 times the units of p q): the position derivative of the
// spring's stiffness met by two vectors, which the exact adjoint of a step needs (the step's matrix
// holds B). `definite` as for spring_jacobian (its transverse term is cut at the rest length, so this is
// the derivative from the side the spring is on). Zero for degenerate and zero-rest-length springs.
Vec3 spring_jacobian_derivative(const BucklingSpring& sp, const VecX& x, bool definite, const Vec3& p, const Vec3& q);

// What the exact adjoint needs of a spring at the positions `state` came from (spring_force_and_definite_jacobian),
// without forming a matrix: Bp = spring_jacobian(sp, x, false) p (B is symmetric) and, when `derivative` is
// true, dpq = spring_jacobian_derivative(sp, x, true, p, q) (else 0); equal to those to round-off.
void spring_adjoint_products(const BucklingSpring& sp, const SpringState& state, bool derivative, const Vec3& p,
                             const Vec3& q, Vec3& Bp, Vec3& dpq);

}  // namespace kf
