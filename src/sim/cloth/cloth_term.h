#pragma once
// What a cloth force term is: a force on a small stencil of particles with its energy (for the step's
// energy check), its force, the definite Jacobians the step solves with, and the products the exact
// adjoint needs. One loop (ClothAssembly) sums every term of the list in cloth_terms.h; the terms are
// types visited at compile time, so a stencil costs no virtual call.
//
// The step (ClothSystem) solves A dv = b with A = M - hs D - hs^2 K and b = hs (f + hs K v + u), where f is
// the sum of the terms' forces and K, D the sums of their definite df/dx and df/dv (-K and -D positive
// semi-definite, symmetric). Its exact adjoint, with w = A^-1 (vhat1 / theta + h xhat1) and
// c = v + dv, is
//   xhat += hs (df/dx)^T w + hs^2 d/dx [w^T K(x, v) c] + hs d/dx [w^T D(x, v) dv]
//   vhat += hs (df/dv - D)^T w + hs^2 d/dv [w^T K(x, v) c] + hs d/dv [w^T D(x, v) dv]
// (beside M w, which the system adds). Every term supplies its share of the first line; the second line is
// zero for a term whose definite D is its exact df/dv and whose K and D do not depend on v (every term
// today but one with velocity-dependent Jacobians, like friction), which says so by leaving
// kVelocityAdjoint false. The swap adjoint (ClothAdjoint::exact false) drops the derivative terms.
//
// Two stencils:
//   kParticle: one particle. `add` adds its force and definite blocks to the particle's row; the adjoint
//              adds its share of xhat_i / hs and vhat_i / hs to an AdjointRow, and a term coupling
//              particles beyond its row (self-contact) adds the rest in `add_adjoint_coupled`.
//   kSpring:   the two ends a, b of a spring (ClothSprings): `write` puts the force on a and the blocks
//              B = d f_a / d x_b, Bd = d f_a / d v_b into the spring's own slot (the 6x6 stiffness is
//              [[-B, B], [B, -B]]); each particle gathers its springs' slots in a fixed order. The first
//              spring term of the list measures the spring (SpringState) and assigns f and B; later ones
//              add (the same for its adjoint's t). A spring term acts on the springs [0, springs()) (the
//              list is ordered so the damped ones come first; the first term acts on all); a term with
//              kDampingSlot writes Bd (the first such term assigns it).
// Defaults (ClothTermDefaults): no energy, no adjoint products, no velocity adjoint.
#include <memory>
#include <vector>

#include "core/types.h"
#include "scene/cloth_spec.h"
#include "sim/cloth/buckling_spring.h"
#include "sim/cloth/cloth_springs.h"
#include "sim/cloth/collider.h"

namespace kf {

enum class ClothStencil { kParticle, kSpring };

// Energy (J) of a cloth state by kind; the step's check measures what the step moves with it.
struct ClothEnergy {
  double kinetic = 0, gravity = 0, elastic = 0, contact = 0;
  double total() const { return kinetic + gravity + elastic + contact; }
};

// What a term is built from: the scene's cloth, its springs and the colliders (the spec's, then a
// character's body and self-contact), all owned by the system and alive as long as the term.
struct ClothTermSetup {
  const ClothSpec& spec;
  const ClothSprings& springs;
  const std::vector<std::unique_ptr<Collider>>& colliders;
};

// The state every term sees at one (sub)step: step n, positions x (3p, m), velocities v (3p, m/s), the
// particles' masses (p, kg) and which particles are free (pinned ones are 0).
struct ClothState {
  int n;
  const VecX& x;
  const VecX& v;
  const VecX& mass;
  const std::vector<char>& free;
};

// One particle's row of the step: force (N) and the diagonal blocks of the definite K (N/m) and D (N s/m).
struct ParticleRow {
  Vec3 f = Vec3::Zero();
  Mat3 K = Mat3::Zero();
  Mat3 D = Mat3::Zero();
};

// One spring's slot: the force on its end a (N), B (N/m) and Bd (N s/m) as above.
struct SpringSlot {
  Vec3& f;
  Mat3& B;
  Mat3& Bd;
};

// What the adjoint of one substep gives the terms: the state it starts from (x, v at step n; masses, kg),
// its length hs = theta h (s), the solve's w (3p, 0 on pins), c = v + dv and dv (3p), and whether it is the
// exact adjoint.
struct ClothAdjoint {
  int n;
  double hs;
  bool exact;
  const VecX& x;
  const VecX& v;
  const VecX& mass;
  const VecX& w;
  const VecX& c;
  const VecX& dv;
};

// A particle's share of the adjoint, before the factor hs: x gets (df/dx)^T w + hs d/dx[w^T K c] +
// d/dx[w^T D dv] at this particle, v the velocity counterpart (see the header comment).
struct AdjointRow {
  Vec3 x = Vec3::Zero();
  Vec3 v = Vec3::Zero();
};

// The defaults a term inherits and hides what it has.
struct ClothTermDefaults {
  // Which ClothEnergy part the term's energy goes to (nullptr: it stores none, like damping). A term
  // counted in `contact` may depend on n (a moving collider); the others depend on the state only.
  static constexpr double ClothEnergy::*kEnergy = nullptr;
  // True when the term's K or D depends on v or its D is not its exact df/dv (see the header comment).
  static constexpr bool kVelocityAdjoint = false;
  // kSpring: true when the term writes the slot's Bd.
  static constexpr bool kDampingSlot = false;

  // kParticle: adds particle i's energy (J) to e.
  void add_energy(const ClothState&, int /*i*/, double& /*e*/) const {}
  // kParticle: adds particle i's share of the adjoint to `row`.
  void add_adjoint(const ClothAdjoint&, int /*i*/, AdjointRow& /*row*/) const {}
  // kParticle: adds what couples particles beyond their own rows straight into xhat and vhat (3p), after
  // every row is done.
  void add_adjoint_coupled(const ClothAdjoint&, VecX& /*xhat*/, VecX& /*vhat*/) const {}
  // kSpring: spring k's energy (J) at positions x.
  double energy(const VecX& /*x*/, int /*k*/) const { return 0.0; }
  // kSpring: the conservative part of the force on end a at positions x (N): what a pin works against.
  Vec3 conservative_force(const VecX& /*x*/, int /*k*/) const { return Vec3::Zero(); }
  // kSpring: adds to t (xhat_a / hs; xhat_b gets its negative) spring k's share of the adjoint, with
  // dw = w_b - w_a and `derivative` whether the exact derivative terms are wanted (exact and dw != 0).
  void spring_adjoint(const ClothAdjoint&, int /*k*/, const SpringState&, const Vec3& /*dw*/, bool /*derivative*/,
                      Vec3& /*t*/) const {}
  // kSpring with kVelocityAdjoint: adds to t (vhat_a / hs; vhat_b gets its negative) its velocity share.
  void spring_adjoint_v(const ClothAdjoint&, int /*k*/, const SpringState&, const Vec3& /*dw*/, bool /*derivative*/,
                        Vec3& /*t*/) const {}
};

}  // namespace kf
