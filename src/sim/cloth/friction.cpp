#include "sim/cloth/friction.h"

#include <cmath>

namespace kf {

// With t = P u, s = 1 / sqrt(t.t + eps^2): f = -L s t, df/dt = -L Q with Q = s I - s^3 t t^T, dt/du = P and
// dt/dn = -(n.u) I - n u^T.
FrictionForce friction_force(double limit, const Vec3& n, const Vec3& u, double eps) {
  FrictionForce out;
  const double nu = n.dot(u);
  const Vec3 t = u - nu * n;
  const double s = 1 / std::sqrt(t.squaredNorm() + eps * eps);
  const Mat3 Q = s * Mat3::Identity() - (s * s * s) * t * t.transpose();
  const Mat3 P = Mat3::Identity() - n * n.transpose();
  out.f = -limit * s * t;
  out.dfdL = -s * t;
  // Q P = s P - s^3 t t^T for a unit n (t^T P = t^T): written so, it is exactly symmetric.
  out.dfdu = -limit * (s * P - (s * s * s) * t * t.transpose());
  out.damping = -limit * s * P;
  out.dfdn = -limit * Q * (-nu * Mat3::Identity() - n * u.transpose());
  return out;
}

// G = a^T D b = -L s pi, pi = a^T P b; ds/dt = -s^3 t.
FrictionDampingDerivative friction_damping_derivative(double limit, const Vec3& n, const Vec3& u, double eps,
                                                      const Vec3& a, const Vec3& b) {
  FrictionDampingDerivative out;
  const double nu = n.dot(u), an = a.dot(n), bn = b.dot(n);
  const Vec3 t = u - nu * n;
  const double s = 1 / std::sqrt(t.squaredNorm() + eps * eps);
  const double pi = a.dot(b) - an * bn;
  out.dL = -s * pi;
  // dG/dt, then through t = P u and t's dependence on n.
  const Vec3 dt = limit * s * s * s * pi * t;
  out.du = dt - n.dot(dt) * n;
  out.dn = limit * s * (bn * a + an * b) - nu * dt - u * n.dot(dt);
  return out;
}

}  // namespace kf
