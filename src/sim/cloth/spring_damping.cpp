#include "sim/cloth/spring_damping.h"

namespace kf {

namespace {
// At or below this fraction of the rest length (at s = 0 for L = 0) a spring has no direction to damp along.
constexpr double kDegenerate = 1e-9;

// The spring's length and direction at x (what damping needs of a SpringState).
SpringState direction(const BucklingSpring& sp, const VecX& x) {
  SpringState st;
  const Vec3 d = seg(x, sp.b) - seg(x, sp.a);
  st.s = d.norm();
  if (st.s > 0) st.n = d / st.s;
  return st;
}
}  // namespace

Vec3 damping_force(const BucklingSpring& sp, double c, const SpringState& state, const VecX& v) {
  if (state.s <= kDegenerate * sp.rest) return Vec3::Zero();
  return c * state.n.dot(seg(v, sp.b) - seg(v, sp.a)) * state.n;
}

Mat3 damping_jacobian_v(const BucklingSpring& sp, double c, const SpringState& state) {
  if (state.s <= kDegenerate * sp.rest) return Mat3::Zero();
  return c * state.n * state.n.transpose();
}

Vec3 damping_force(const BucklingSpring& sp, double c, const VecX& x, const VecX& v) {
  return damping_force(sp, c, direction(sp, x), v);
}

Mat3 damping_jacobian_v(const BucklingSpring& sp, double c, const VecX& x) {
  return damping_jacobian_v(sp, c, direction(sp, x));
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

Vec3 damping_adjoint_products(const BucklingSpring& sp, double c, const SpringState& state, const VecX& v,
                              const Vec3& p, bool derivative, const Vec3& q) {
  const double s = state.s;
  if (s <= kDegenerate * sp.rest) return Vec3::Zero();
  const Vec3& n = state.n;
  const Vec3 dv = seg(v, sp.b) - seg(v, sp.a);
  // J = c (n (P dv)^T + (n . dv) P) with P = (I - n n^T) / s symmetric, so J^T p = c ((n . p) P dv + (n . dv) P p).
  const double pn = p.dot(n), dvn = dv.dot(n);
  const Vec3 Pp = (p - pn * n) / s;
  Vec3 r = c * (pn * (dv - dvn * n) / s + dvn * Pp);
  if (derivative) {
    const double qn = q.dot(n);
    r += c * (qn * Pp + pn * (q - qn * n) / s);  // damping_jacobian_v_derivative
  }
  return r;
}

}  // namespace kf
