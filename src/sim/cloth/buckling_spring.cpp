#include "sim/cloth/buckling_spring.h"

#include <cmath>

namespace kf {

namespace {
// Below this fraction of the rest length the direction of a spring is meaningless.
constexpr double kDegenerate = 1e-9;

// The transverse stiffness t (N/m) of B and its slope dt/ds at length s with tension T, slope dT.
// Exact: T/s. Definite: 0 in compression, T/s from a strain of sp.transverse_ramp on, and T/s faded in by a
// smoothstep in between: never negative, so -K stays semi-definite, and C1 in s (a plain cut at the rest
// length puts a kink into the step map at every spring that crosses it, and the optimiser stalls on
// them). It adds no stiffness the force does not have; what it leaves out acts explicitly, and a narrower
// ramp puts more into the implicit solve, which backward Euler damps (ClothSpec::transverse_ramp).
void transverse_stiffness(const BucklingSpring& sp, double s, double T, double dT, bool definite, double& t,
                          double& dt) {
  t = T / s;
  dt = (dT - T / s) / s;
  if (!definite) return;
  const double ramp = sp.transverse_ramp * sp.rest, e = s - sp.rest;
  if (e <= 0) {
    t = dt = 0;
  } else if (e < ramp) {
    const double u = e / ramp, fade = u * u * (3 - 2 * u), dfade = 6 * u * (1 - u) / ramp;
    dt = dt * fade + t * dfade;
    t *= fade;
  }
}
}  // namespace

namespace {

// The Choi-Ko compression law at compression e > 0 and its first two derivatives in e (not s).
struct Compression {
  double T, T_e, T_ee;
};
Compression choi_ko(const BucklingSpring& sp, double e) {
  const double soft = sp.k - sp.k_post, a = soft / sp.f_buckle, decay = std::exp(-a * e);
  return {-(sp.f_buckle * (1.0 - decay) + sp.k_post * e), -(soft * decay + sp.k_post), soft * a * decay};
}

// Energy of the Choi-Ko law alone from 0 to e (J); -expm1 keeps the small-e end accurate.
double choi_ko_energy(const BucklingSpring& sp, double e) {
  const double soft = sp.k - sp.k_post;
  return sp.f_buckle * e + sp.f_buckle * sp.f_buckle / soft * std::expm1(-soft * e / sp.f_buckle) +
         0.5 * sp.k_post * e * e;
}

// Compressions below e0 blend the linear law -k e into Choi-Ko's with a quintic smoothstep.
double blend_end(const BucklingSpring& sp) { return kBuckleBlend * sp.f_buckle / (sp.k - sp.k_post); }

Compression blended(const BucklingSpring& sp, double e) {
  const double e0 = blend_end(sp);
  const Compression c = choi_ko(sp, e);
  if (e >= e0) return c;
  const double u = e / e0;
  const double w = u * u * u * (10 - 15 * u + 6 * u * u), w_e = 30 * u * u * (1 - u) * (1 - u) / e0,
               w_ee = 60 * u * (1 - u) * (1 - 2 * u) / (e0 * e0);
  const double d = c.T + sp.k * e, d_e = c.T_e + sp.k, d_ee = c.T_ee;  // Choi-Ko less the linear law
  return {-sp.k * e + w * d, -sp.k + w_e * d + w * d_e, w_ee * d + 2 * w_e * d_e + w * d_ee};
}

bool buckles(const BucklingSpring& sp) { return sp.f_buckle > 0 && sp.k > sp.k_post; }

}  // namespace

void spring_tension(const BucklingSpring& sp, double s, double& T, double& dT_ds, double& d2T_ds2) {
  const double e = sp.rest - s;
  if (e <= 0 || !buckles(sp)) {
    T = -sp.k * e;
    dT_ds = sp.k;
    d2T_ds2 = 0;
    return;
  }
  const Compression c = blended(sp, e);
  T = c.T;
  dT_ds = -c.T_e;  // ds = -de
  d2T_ds2 = c.T_ee;
}

namespace {
// The blend's energy in closed form. With U = e / e0 and a e0 = kBuckleBlend = beta for every spring, the
// blended tension is T = k e0 (-U + w(U) (1 - k_p / k) g(U)), w the quintic smoothstep and
// g(u) = u - (1 - exp(-beta u)) / beta, so the energy stored from 0 to U is
//     E = e0^2 (k U^2 / 2 - (k - k_p) G(U)),   G(U) = integral from 0 to U of w(u) g(u) du,
// one function for every spring. G is a power series: g(u) = sum_{n >= 2} (-1)^n beta^(n-1) u^n / n!, whose
// terms fall below round-off by n = 20 for beta u <= 1/2; integrated against w's three monomials, that
// gives G's coefficients (a buckled sheet's energy check cost a tenth of its step by 8-point quadrature,
// 8 exponentials a spring).
class BlendEnergy {
 public:
  BlendEnergy() {
    double c = kBuckleBlend / 2;  // (-1)^n beta^(n-1) / n! at n = 2
    for (int n = 2; n <= kTerms; ++n) {
      a_[n + 4] += 10 * c / (n + 4);
      a_[n + 5] -= 15 * c / (n + 5);
      a_[n + 6] += 6 * c / (n + 6);
      c *= -kBuckleBlend / (n + 1);
    }
  }
  double G(double U) const {
    double g = 0;
    for (int m = kTerms + 6; m >= 0; --m) g = g * U + a_[m];
    return g;
  }

 private:
  static constexpr int kTerms = 20;
  double a_[kTerms + 7] = {};  // a_[m]: the coefficient of U^m
};
}  // namespace

double spring_energy(const BucklingSpring& sp, const VecX& x) {
  const Vec3 d = seg(x, sp.b) - seg(x, sp.a);
  if (sp.rest == 0) return 0.5 * sp.k * d.squaredNorm();
  const double e = sp.rest - d.norm();
  if (e <= 0 || !buckles(sp)) return 0.5 * sp.k * e * e;
  static const BlendEnergy blend;
  // E(e) = -integral of T from 0 to e: the blend's in closed form up to e0, Choi-Ko's beyond.
  const double e0 = blend_end(sp), U = std::min(e, e0) / e0;
  double energy = e0 * e0 * (0.5 * sp.k * U * U - (sp.k - sp.k_post) * blend.G(U));
  if (e > e0) energy += choi_ko_energy(sp, e) - choi_ko_energy(sp, e0);
  return energy;
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

void spring_force_and_definite_jacobian(const BucklingSpring& sp, const VecX& x, Vec3& f, Mat3& B,
                                        SpringState& state) {
  const Vec3 d = seg(x, sp.b) - seg(x, sp.a);
  const double s = d.norm();
  state.s = s;
  state.n = s > 0 ? Vec3(d / s) : Vec3::Zero();
  if (sp.rest == 0) {
    f = sp.k * d;
    B = sp.k * Mat3::Identity();
    return;
  }
  double T, dT, d2T;
  spring_tension(sp, s, T, dT, d2T);
  state.T = T;
  state.dT = dT;
  state.d2T = d2T;
  if (s <= kDegenerate * sp.rest) {
    f.setZero();
    B = dT * Mat3::Identity();
    return;
  }
  f = (T / s) * d;
  const Vec3& n = state.n;
  const Mat3 nn = n * n.transpose();
  double t, dt;
  transverse_stiffness(sp, s, T, dT, /*definite=*/true, t, dt);
  B = dT * nn + t * (Mat3::Identity() - nn);
}

void spring_adjoint_products(const BucklingSpring& sp, const SpringState& state, bool derivative, const Vec3& p,
                             const Vec3& q, Vec3& Bp, Vec3& dpq) {
  dpq.setZero();
  if (sp.rest == 0) {
    Bp = sp.k * p;
    return;
  }
  const double s = state.s, T = state.T, dT = state.dT, d2T = state.d2T;
  if (s <= kDegenerate * sp.rest) {
    Bp = dT * p;
    return;
  }
  const Vec3& n = state.n;
  const double pn = p.dot(n);
  double t, dt;
  transverse_stiffness(sp, s, T, dT, /*definite=*/false, t, dt);
  Bp = t * p + (dT - t) * pn * n;  // dT n n^T p + t (I - n n^T) p
  if (!derivative) return;
  transverse_stiffness(sp, s, T, dT, /*definite=*/true, t, dt);
  const double qn = q.dot(n);
  const Vec3 dpn = (p - pn * n) / s, dqn = (q - qn * n) / s;
  dpq = ((d2T - dt) * pn * qn + dt * p.dot(q)) * n + (dT - t) * (qn * dpn + pn * dqn);
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
