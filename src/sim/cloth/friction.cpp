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
  // Q P = s P - s^3 t t^T for a unit n (t^T P = t^T): written so, it is exactly symmetric, and it is the
  // form friction_damping_derivative differentiates.
  out.dfdu = -limit * (s * P - (s * s * s) * t * t.transpose());
  out.dfdn = -limit * Q * (-nu * Mat3::Identity() - n * u.transpose());
  return out;
}

// G = a^T (df/du) b = -L (s pi - s^3 alpha beta), pi = a^T P b, alpha = a.t, beta = b.t.
FrictionDampingDerivative friction_damping_derivative(double limit, const Vec3& n, const Vec3& u, double eps,
                                                      const Vec3& a, const Vec3& b) {
  FrictionDampingDerivative out;
  const double nu = n.dot(u), an = a.dot(n), bn = b.dot(n);
  const Vec3 t = u - nu * n;
  const double s = 1 / std::sqrt(t.squaredNorm() + eps * eps), s3 = s * s * s;
  const double pi = a.dot(b) - an * bn, alpha = a.dot(t), beta = b.dot(t);
  out.dL = -(s * pi - s3 * alpha * beta);
  // dG/dt, then through t = P u and t's dependence on n.
  const Vec3 dt = limit * s3 * ((pi - 3 * s * s * alpha * beta) * t + beta * a + alpha * b);
  out.du = dt - n.dot(dt) * n;
  out.dn = limit * s * (bn * a + an * b) - nu * dt - u * n.dot(dt);
  return out;
}

}  // namespace kf
