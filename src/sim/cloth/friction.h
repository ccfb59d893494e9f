#pragma once
// Smoothed Coulomb friction on one contact, and the derivatives the linearised step and its exact adjoint
// need.
//
// A contact pressed by a normal force of magnitude lambda (N) along the unit normal n, sliding with
// relative velocity u (m/s), feels
//     f = -L t / sqrt(|t|^2 + eps^2),   t = P u,  P = I - n n^T,  L = mu lambda,
// Coulomb's friction of magnitude L against the tangential slip t once |t| >> eps, and a viscous drag
// L / eps below it (eps, m/s: the slip speed under which the contact counts as sticking). The normal force
// is the contact's own at the state the step starts from, as every force of the linearised step is (so
// it is "lagged" as in IPC's friction: the implicit solve holds it fixed), and the step's exact adjoint
// differentiates through it.
//
// The damping block the step's matrix holds is not df/du but the drag coefficient at the step's start,
// D = -(L / r) P, r = sqrt(|t|^2 + eps^2): since f = D u, the step's friction is then -(L / r) P u1, a drag
// taken implicitly on the slip after the step, which shrinks the slip and never reverses it (for one
// particle the slip map's slope stays below 1). With df/du there (-L eps^2 / r^3 along a sliding slip) the
// step pushes a sliding particle with nearly the explicit Coulomb force, its slip overshoots zero by more
// than it had whenever h L / m exceeds a few eps, and perturbations grow several times per step wherever
// sheets slide in contact. The adjoint adds df/du - D (symmetric: L t t^T / r^3) as the part of the force's
// velocity derivative the matrix does not hold.
//
// Why not IPC's mollifier f1(y) = 2y/eps - y^2/eps^2: its velocity Jacobian holds |t| terms, so the
// step's matrix has a kink at zero slip, where sticking particles sit, and another at |t| = eps; the exact
// adjoint differentiates that matrix. f and D here are C-infinity in u, and D is symmetric and negative
// semi-definite, so it can sit in the step's matrix as a damping block.
#include "core/types.h"

namespace kf {

// f and its derivatives in u, L and n (dfdn: n varying freely, not kept unit; callers chain dn/dx, whose
// range is tangent, so only that part counts).
struct FrictionForce {
  Vec3 f = Vec3::Zero();       // N
  Mat3 damping = Mat3::Zero(); // N s/m: D = -(L / r) P, what the step's matrix holds (symmetric, NSD)
  Mat3 dfdu = Mat3::Zero();    // N s/m: the exact df/du (symmetric, negative semi-definite)
  Vec3 dfdL = Vec3::Zero();    // 1
  Mat3 dfdn = Mat3::Zero();    // N
};
// limit: L = mu lambda >= 0 (N); n: unit normal; u: relative velocity (m/s); eps > 0 (m/s).
FrictionForce friction_force(double limit, const Vec3& n, const Vec3& u, double eps);

// The derivatives of a^T D b in u, L and n (D = FrictionForce::damping), for fixed vectors a, b: what the
// exact adjoint of the linearised step needs of the damping block (a = the adjoint solve's w, b = the step's velocity change).
struct FrictionDampingDerivative {
  Vec3 du = Vec3::Zero();
  double dL = 0;
  Vec3 dn = Vec3::Zero();
};
FrictionDampingDerivative friction_damping_derivative(double limit, const Vec3& n, const Vec3& u, double eps,
                                                      const Vec3& a, const Vec3& b);

// Friction settings of one collider (scene keys): the coefficient and the sticking speed.
struct FrictionParams {
  double mu = 0;        // Coulomb coefficient (0: frictionless)
  double eps = 0.01;    // m/s
  bool on() const { return mu > 0; }
};

}  // namespace kf
