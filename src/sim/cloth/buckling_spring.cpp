#include "sim/cloth/buckling_spring.h"

#include <cmath>

namespace kf {

namespace {
// Below this fraction of the rest length the direction of a spring is meaningless.
constexpr double kDegenerate = 1e-9;

// The transverse stiffness t (N/m) of B and its slope dt/ds at length s with tension T, slope dT.
// Exact: T/s. Definite: 0 in compression, T/s from a strain of kTransverseRamp on, and T/s faded in by a
// smoothstep in between: never negative, so -K stays semi-definite, and C1 in s (a plain cut at the rest
// length puts a kink into the step map at every spring that crosses it, and the optimiser stalls on
// them). It adds no stiffness the force does not have, so it damps nothing.
void transverse_stiffness(const BucklingSpring& sp, double s, double T, double dT, bool definite, double& t,
                          double& dt) {
  t = T / s;
  dt = (dT - T / s) / s;
  if (!definite) return;
  const double ramp = kTransverseRamp * sp.rest, e = s - sp.rest;
  if (e <= 0) {
    t = dt = 0;
  } else if (e < ramp) {
    const double u = e / ramp, fade = u * u * (3 - 2 * u), dfade = 6 * u * (1 - u) / ramp;
    dt = dt * fade + t * dfade;
    t *= fade;
  }
}
}  // namespace

void spring_tension(const BucklingSpring& sp, double s, double& T, double& dT_ds, double& d2T_ds2) {
  const double e = sp.rest - s;
  if (e <= 0 || sp.f_buckle <= 0) {
    T = -sp.k * e;
    dT_ds = sp.k;
    d2T_ds2 = 0;
    return;
  }
  const double soft = sp.k - sp.k_post;
  const double decay = std::exp(-soft * e / sp.f_buckle);
  T = -(sp.f_buckle * (1.0 - decay) + sp.k_post * e);
  dT_ds = soft * decay + sp.k_post;
  d2T_ds2 = soft * soft / sp.f_buckle * decay;
}

double spring_energy(const BucklingSpring& sp, const VecX& x) {
  const Vec3 d = seg(x, sp.b) - seg(x, sp.a);
  if (sp.rest == 0) return 0.5 * sp.k * d.squaredNorm();
  const double e = sp.rest - d.norm();
  const double soft = sp.k - sp.k_post;
  if (e <= 0 || sp.f_buckle <= 0 || soft <= 0) return 0.5 * sp.k * e * e;
  // -expm1 keeps the small-e end accurate (there the energy is k e^2 / 2 to leading order).
  return sp.f_buckle * e + sp.f_buckle * sp.f_buckle / soft * std::expm1(-soft * e / sp.f_buckle) +
         0.5 * sp.k_post * e * e;
}

Vec3 spring_force(const BucklingSpring& sp, const VecX& x) {
  const Vec3 d = seg(x, sp.b) - seg(x, sp.a);
  // Zero rest length: T/s = k at every length, so the force k d needs no direction (s = 0 included).
  if (sp.rest == 0) return sp.k * d;
  const double s = d.norm();
  if (s <= kDegenerate * sp.rest) return Vec3::Zero();
  double T, dT, d2T;
  spring_tension(sp, s, T, dT, d2T);
  return (T / s) * d;
}

Mat3 spring_jacobian(const BucklingSpring& sp, const VecX& x, bool definite) {
  // Zero rest length: dT/ds = T/s = k, so the axial and transverse parts agree and B = k I exactly.
  if (sp.rest == 0) return sp.k * Mat3::Identity();
  const Vec3 d = seg(x, sp.b) - seg(x, sp.a);
  const double s = d.norm();
  double T, dT, d2T;
  spring_tension(sp, s, T, dT, d2T);
  if (s <= kDegenerate * sp.rest) return dT * Mat3::Identity();
  const Vec3 n = d / s;
  const Mat3 nn = n * n.transpose();
  double t, dt;
  transverse_stiffness(sp, s, T, dT, definite, t, dt);
  return dT * nn + t * (Mat3::Identity() - nn);
}

Vec3 spring_jacobian_derivative(const BucklingSpring& sp, const VecX& x, bool definite, const Vec3& p, const Vec3& q) {
  if (sp.rest == 0) return Vec3::Zero();
  const Vec3 d = seg(x, sp.b) - seg(x, sp.a);
  const double s = d.norm();
  if (s <= kDegenerate * sp.rest) return Vec3::Zero();
  double T, dT, d2T;
  spring_tension(sp, s, T, dT, d2T);
  // B = (a - t) n n^T + t I with a = dT/ds and t the transverse stiffness, so
  // p.B q = (a - t)(p.n)(q.n) + t p.q, dn/dd = (I - n n^T)/s.
  const Vec3 n = d / s;
  double t, dt;
  transverse_stiffness(sp, s, T, dT, definite, t, dt);
  const double pn = p.dot(n), qn = q.dot(n);
  const Vec3 dpn = (p - pn * n) / s, dqn = (q - qn * n) / s;
  return ((d2T - dt) * pn * qn + dt * p.dot(q)) * n + (dT - t) * (qn * dpn + pn * dqn);
}

}  // namespace kf
