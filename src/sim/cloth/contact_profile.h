#pragma once
// How hard a contact pushes at penetration depth delta = thickness - phi: the force magnitude g(delta)
// along the contact normal, and its first two derivatives.
//
// A linear penalty g = k delta switches its stiffness from 0 to k where contact begins, so the step map,
// and the objective with it, has a kink there. With a ramp of width r the stiffness rises smoothly:
//     g'(delta) = k (3 t^2 - 2 t^3),  t = delta / r  (0 <= t <= 1),   g'(delta) = k beyond,
// so g is C2, its stiffness C1, and the linearised step (whose matrix holds g') is C1 where contacts
// begin and end. Deeper than r the force is k (delta - r/2): the linear penalty shifted by half the ramp.
// ramp = 0 gives the linear penalty.
namespace kf {

struct ContactProfile {
  double stiffness = 0;  // k, N/m
  double ramp = 0;       // r, metres

  // Force magnitude g (N), stiffness g' (N/m) and g'' (N/m^2) at depth delta (m); all 0 for delta <= 0.
  void eval(double delta, double& g, double& dg, double& ddg) const {
    if (delta <= 0) {
      g = dg = ddg = 0;
    } else if (delta >= ramp) {
      g = stiffness * (delta - 0.5 * ramp);
      dg = stiffness;
      ddg = 0;
    } else {
      const double t = delta / ramp;
      g = stiffness * ramp * t * t * t * (1 - 0.5 * t);
      dg = stiffness * t * t * (3 - 2 * t);
      ddg = stiffness / ramp * 6 * t * (1 - t);
    }
  }

  // Energy stored at depth delta (J): the integral of g from 0 to delta.
  double energy(double delta) const {
    if (delta <= 0) return 0;
    if (delta >= ramp) return stiffness * (0.5 * delta * delta - 0.5 * ramp * delta + 0.15 * ramp * ramp);
    const double t = delta / ramp;
    return stiffness * ramp * ramp * t * t * t * t * (0.25 - 0.1 * t);
  }
};

}  // namespace kf
