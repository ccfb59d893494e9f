#include "sim/cloth/spring_damping.h"

namespace kf {

namespace {
// At or below this fraction of the rest length (at s = 0 for L = 0) a spring has no direction to damp along.
constexpr double kDegenerate = 1e-9;
}

Vec3 damping_force(const BucklingSpring& sp, double c, const VecX& x, const VecX& v) {
  const Vec3 d = seg(x, sp.b) - seg(x, sp.a);
  const double s = d.norm();
  if (s <= kDegenerate * sp.rest) return Vec3::Zero();
  const Vec3 n = d / s;
  return c * n.dot(seg(v, sp.b) - seg(v, sp.a)) * n;
}

Mat3 damping_jacobian_v(const BucklingSpring& sp, double c, const VecX& x) {
  const Vec3 d = seg(x, sp.b) - seg(x, sp.a);
  const double s = d.norm();
  if (s <= kDegenerate * sp.rest) return Mat3::Zero();
  const Vec3 n = d / s;
  return c * n * n.transpose();
}

Mat3 damping_jacobian_x(const BucklingSpring& sp, double c, const VecX& x, const VecX& v) {
  const Vec3 d = seg(x, sp.b) - seg(x, sp.a);
  const double s = d.norm();
  if (s <= kDegenerate * sp.rest) return Mat3::Zero();
  const Vec3 n = d / s, dv = seg(v, sp.b) - seg(v, sp.a);
  const Mat3 P = (Mat3::Identity() - n * n.transpose()) / s;  // dn/dd
  return c * (n * (P * dv).transpose() + n.dot(dv) * P);
}

Vec3 damping_jacobian_v_derivative(const BucklingSpring& sp, double c, const VecX& x, const Vec3& p, const Vec3& q) {
  const Vec3 d = seg(x, sp.b) - seg(x, sp.a);
  const double s = d.norm();
  if (s <= kDegenerate * sp.rest) return Vec3::Zero();
  const Vec3 n = d / s;
  const double pn = p.dot(n), qn = q.dot(n);
  return c * (qn * (p - pn * n) + pn * (q - qn * n)) / s;
}

}  // namespace kf
