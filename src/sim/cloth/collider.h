#pragma once
// Colliders push cloth particles out with stiff springs that switch on within a thickness of the surface.
//
// A collider acts on one particle at a time, so a moving character mesh (closest point per particle) fits
// the same interface as one more collider; pair contacts (self-collision) add their cross couplings
// through the whole-cloth methods. The force of a collider with signed distance phi(x) (outside positive)
// and outward unit normal n(x) is f = g(thickness - phi) n, g the ContactProfile (0 outside).
//
// Jacobians: the exact df/dx = -g' n n^T + g dn/dx; the definite one (what the implicit matrix holds)
// keeps -g' n n^T. The exact adjoint also needs the position derivative of that definite block met by
// two vectors (definite_stiffness_derivative).
//
// Friction (FrictionParams, sim/cloth/friction.h; the cloth's FrictionTerm sums it) is the smoothed Coulomb
// force of limit mu g against the velocity relative to the surface, apart from contact(). Its damping block
// D (the drag coefficient at the step's start, friction.h: symmetric, negative semi-definite, held by the
// implicit matrix) is not its df/dv; the rest of df/dv and its df/dx (through g, n and, on a moving surface,
// the surface's velocity at the closest point) are only in the exact Jacobian. Since D depends on x and v,
// the exact adjoint also needs d/dx and d/dv of w . D(x, v) c (damping_derivative).
#include <memory>
#include <vector>

#include "core/types.h"
#include "scene/cloth_spec.h"
#include "sim/cloth/contact_profile.h"
#include "sim/cloth/friction.h"

namespace kf {

struct ContactForce {
  Vec3 f = Vec3::Zero();           // N
  Mat3 dfdx = Mat3::Zero();        // N/m
  Mat3 dfdv = Mat3::Zero();        // N s/m: the damping block the implicit matrix holds
  // N s/m: the exact df/dv less dfdv, when `exact` (friction's lagged drag coefficient, friction.h); else 0.
  Mat3 dfdv_rest = Mat3::Zero();
};

class Collider {
 public:
  virtual ~Collider() = default;
  // What a summary calls a collider the system adds beyond the scene's own (which are named by their type).
  virtual const char* name() const { return "added"; }
  // The state (x, v: 3p) every contact query until the next call is about: the cloth calls it before each
  // assembly. Only a pair collider (self contact) reads it, to find each particle's neighbours.
  virtual void set_state(const VecX& /*x*/, const VecX& /*v*/) {}
  // Contact of a particle at x (m) with velocity v (m/s) at step n. Returns false (and leaves `out`
  // untouched) when there is no contact. `definite` keeps only the Jacobian part that stiffens the
  // implicit matrix (-k n n^T), dropping curvature terms that could make it indefinite; the exact
  // Jacobian is definite = false.
  virtual bool contact(int n, const Vec3& x, const Vec3& v, bool definite, ContactForce& out) const = 0;
  // Energy (J) the contact of a particle at x stores at step n, 0 outside contact. Colliders that move
  // by themselves (a character's body) or act on pairs report 0: the step's energy check cannot account
  // for the work they do.
  virtual double energy(int /*n*/, const Vec3& /*x*/) const { return 0.0; }
  // d/dx [w . Kd(x) c], Kd the definite df/dx of the particle at x (zero out of contact).
  virtual Vec3 definite_stiffness_derivative(int n, const Vec3& x, const Vec3& w, const Vec3& c) const = 0;

  // Whole-cloth forms for the adjoint (x, w, c, out: 3p). add_definite_stiffness_derivative adds
  // scale * d/dx [w^T Kd(x) c]; the default sums the per-particle derivative (parallel over particles).
  virtual void add_definite_stiffness_derivative(int n, const VecX& x, const VecX& w, const VecX& c, double scale,
                                                 VecX& out) const;
  // Adds scale * C^T w, C the blocks of the exact df/dx that couple two particles (none by default).
  virtual void add_cross_transpose(int /*n*/, const VecX& /*w*/, double /*scale*/, VecX& /*out*/) const {}

  // Friction of the particle at x moving with v at step n (FrictionParams; sim/cloth/friction.h): its force,
  // its damping block dfdv (what the implicit matrix holds) and, when `exact`, its df/dx and dfdv_rest
  // (else zero).
  // Returns false (and leaves `out` untouched) without friction or contact. A pair collider gathers the
  // particle's pairs here and puts the blocks coupling two particles in add_friction_coupled.
  virtual bool friction(int /*n*/, const Vec3& /*x*/, const Vec3& /*v*/, bool /*exact*/, ContactForce& /*out*/) const {
    return false;
  }
  // d/dx and d/dv of [w . D(x, v) c], D the dfdv (damping block) of friction() (both zero out of contact, without friction,
  // and for pair colliders, which need both ends: add_friction_coupled carries theirs).
  virtual void damping_derivative(int /*n*/, const Vec3& /*x*/, const Vec3& /*v*/, const Vec3& /*w*/,
                                  const Vec3& /*c*/, Vec3& ddx, Vec3& ddv) const {
    ddx.setZero();
    ddv.setZero();
  }
  // A pair collider's friction couplings over the state it was updated with (w, c, xout, vout: 3p):
  // xout += scale * Cx^T w and vout += scale * Cv^T w, Cx and Cv the blocks of the exact df/dx and of
  // df/dv that couple two particles (the implicit matrix holds neither), and, when `exact`, xout += scale
  // * d/dx [w^T D c] and vout += scale * d/dv [w^T D c] over its pairs. Nothing by default.
  virtual void add_friction_coupled(int /*n*/, const VecX& /*w*/, const VecX& /*c*/, double /*scale*/, bool /*exact*/,
                                    VecX& /*xout*/, VecX& /*vout*/) const {}

  const FrictionParams& friction_params() const { return friction_; }
  void set_friction(const FrictionParams& f) { friction_ = f; }

 protected:
  FrictionParams friction_;  // off unless set
};

// A signed-distance collider: the analytic shapes only supply phi, n and dn/dx.
class DistanceCollider : public Collider {
 public:
  // ramp: the width of the contact profile's stiffness ramp, metres (0: linear penalty).
  DistanceCollider(double thickness, double stiffness, double ramp) : thickness_(thickness), profile_{stiffness, ramp} {}
  bool contact(int n, const Vec3& x, const Vec3& v, bool definite, ContactForce& out) const override;
  Vec3 definite_stiffness_derivative(int n, const Vec3& x, const Vec3& w, const Vec3& c) const override;
  bool friction(int n, const Vec3& x, const Vec3& v, bool exact, ContactForce& out) const override;
  void damping_derivative(int n, const Vec3& x, const Vec3& v, const Vec3& w, const Vec3& c, Vec3& ddx,
                          Vec3& ddv) const override;
  double energy(int n, const Vec3& x) const override;
  // Signed distance phi (m), outward unit normal n and dn/dx (3x3, 1/m) at x.
  virtual void distance(const Vec3& x, double& phi, Vec3& normal, Mat3& dnormal_dx) const = 0;

 private:
  double thickness_;
  ContactProfile profile_;
};

class GroundCollider final : public DistanceCollider {
 public:
  GroundCollider(const GroundShape& s, double thickness, double stiffness, double ramp);
  void distance(const Vec3& x, double& phi, Vec3& normal, Mat3& dnormal_dx) const override;

 private:
  Vec3 point_, normal_;
};

class SphereCollider final : public DistanceCollider {
 public:
  SphereCollider(const SphereShape& s, double thickness, double stiffness, double ramp);
  void distance(const Vec3& x, double& phi, Vec3& normal, Mat3& dnormal_dx) const override;

 private:
  Vec3 center_;
  double radius_;
};

// The ring of the ring toss: a torus with major radius R around `axis` and tube radius r.
class TorusCollider final : public DistanceCollider {
 public:
  TorusCollider(const TorusShape& s, double thickness, double stiffness, double ramp);
  void distance(const Vec3& x, double& phi, Vec3& normal, Mat3& dnormal_dx) const override;

 private:
  Vec3 center_, axis_;
  double major_, tube_;
};

// A capsule: distance to the segment a-b minus the radius (a cylinder with hemispherical caps).
class CapsuleCollider final : public DistanceCollider {
 public:
  CapsuleCollider(const CapsuleShape& s, double thickness, double stiffness, double ramp);
  void distance(const Vec3& x, double& phi, Vec3& normal, Mat3& dnormal_dx) const override;

 private:
  Vec3 a_, axis_;  // one end and the unit direction to the other
  double length_, radius_;
};

// A box with rounded edges: the points within `radius` of an oriented inner box (half extents e, which
// may be 0 along an axis). A BoxShape's inner box is its size shrunk by the rounding; a RectangleShape is
// an inner box of no depth and no rounding, so it pushes within its thickness from either side, away from
// its nearest point. phi and n are continuous everywhere but inside the inner box's medial planes, deeper
// than `radius` (a rectangle: only in its own plane, where n is its normal on the side u x v points to).
class BoxCollider final : public DistanceCollider {
 public:
  BoxCollider(const BoxShape& s, double thickness, double stiffness, double ramp);
  BoxCollider(const RectangleShape& s, double thickness, double stiffness, double ramp);
  void distance(const Vec3& x, double& phi, Vec3& normal, Mat3& dnormal_dx) const override;

 private:
  Vec3 center_;
  Mat3 axes_;     // columns: the box's unit axes (world from box)
  Vec3 half_;     // the inner box's half extents along them, metres
  double radius_;
};

// One collider per spec entry, in order, each shape's class chosen by std::visit (empty for a scene without colliders). ramp_fraction: each
// contact profile's ramp as a fraction of its collider's thickness. Each gets its spec's friction.
std::vector<std::unique_ptr<Collider>> make_colliders(const std::vector<ColliderSpec>& specs, double ramp_fraction);

}  // namespace kf
