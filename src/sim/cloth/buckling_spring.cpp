#include "sim/cloth/buckling_spring.h"

#include <cmath>

namespace kf {

namespace {
// Below this fraction of the rest length the direction of a spring is meaningless.
constexpr double kDegenerate = 1e-9;
}  // namespace

void spring_tension(const BucklingSpring& sp, double s, double& T, double& dT_ds) {
  const double e = sp.rest - s;
  if (e <= 0 || sp.f_buckle <= 0) {
    T = -sp.k * e;
    dT_ds = sp.k;
    return;
  }
  const double soft = sp.k - sp.k_post;
  const double decay = std::exp(-soft * e / sp.f_buckle);
  T = -(sp.f_buckle * (1.0 - decay) + sp.k_post * e);
  dT_ds = soft * decay + sp.k_post;
}

Vec3 spring_force(const BucklingSpring& sp, const VecX& x) {
  const Vec3 d = seg(x, sp.b) - seg(x, sp.a);
  // Zero rest length: T/s = k at every length, so the force k d needs no direction (s = 0 included).
  if (sp.rest == 0) return sp.k * d;
  const double s = d.norm();
  if (s <= kDegenerate * sp.rest) return Vec3::Zero();
  double T, dT;
  spring_tension(sp, s, T, dT);
  return (T / s) * d;
}

Mat3 spring_jacobian(const BucklingSpring& sp, const VecX& x, bool definite) {
  // Zero rest length: dT/ds = T/s = k, so the axial and transverse parts agree and B = k I exactly.
  if (sp.rest == 0) return sp.k * Mat3::Identity();
  const Vec3 d = seg(x, sp.b) - seg(x, sp.a);
  const double s = d.norm();
  double T, dT;
  spring_tension(sp, s, T, dT);
  if (s <= kDegenerate * sp.rest) return dT * Mat3::Identity();
  const Vec3 n = d / s;
  const Mat3 nn = n * n.transpose();
  const double transverse = (definite && T < 0) ? 0.0 : T / s;
  return dT * nn + transverse * (Mat3::Identity() - nn);
}

}  // namespace kf
