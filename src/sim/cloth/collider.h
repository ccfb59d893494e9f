#pragma once
// Colliders push cloth particles out with stiff springs that switch on within a thickness of the surface.
//
// A collider acts on one particle at a time, so a moving character mesh (closest point per particle) fits
// the same interface as one more collider. The force of a collider with signed distance phi(x) (outside
// positive) and outward unit normal n(x) is f = k (thickness - phi) n when phi < thickness, else 0.
#include <memory>
#include <vector>

#include "core/types.h"
#include "scene/cloth_spec.h"

namespace kf {

struct ContactForce {
  Vec3 f = Vec3::Zero();           // N
  Mat3 dfdx = Mat3::Zero();        // N/m
  Mat3 dfdv = Mat3::Zero();        // N s/m
};

class Collider {
 public:
  virtual ~Collider() = default;
  // Contact of a particle at x (m) with velocity v (m/s) at step n. Returns false (and leaves `out`
  // untouched) when there is no contact. `definite` keeps only the Jacobian part that stiffens the
  // implicit matrix (-k n n^T), dropping curvature terms that could make it indefinite; the exact
  // Jacobian is definite = false.
  virtual bool contact(int n, const Vec3& x, const Vec3& v, bool definite, ContactForce& out) const = 0;
};

// A signed-distance collider: the three analytic shapes only supply phi, n and dn/dx.
class DistanceCollider : public Collider {
 public:
  DistanceCollider(double thickness, double stiffness) : thickness_(thickness), stiffness_(stiffness) {}
  bool contact(int n, const Vec3& x, const Vec3& v, bool definite, ContactForce& out) const override;
  // Signed distance phi (m), outward unit normal n and dn/dx (3x3, 1/m) at x.
  virtual void distance(const Vec3& x, double& phi, Vec3& normal, Mat3& dnormal_dx) const = 0;

 private:
  double thickness_, stiffness_;
};

class GroundCollider final : public DistanceCollider {
 public:
  GroundCollider(const ColliderSpec& s);
  void distance(const Vec3& x, double& phi, Vec3& normal, Mat3& dnormal_dx) const override;

 private:
  Vec3 point_, normal_;
};

class SphereCollider final : public DistanceCollider {
 public:
  SphereCollider(const ColliderSpec& s);
  void distance(const Vec3& x, double& phi, Vec3& normal, Mat3& dnormal_dx) const override;

 private:
  Vec3 center_;
  double radius_;
};

// The ring of the ring toss: a torus with major radius R around `axis` and tube radius r.
class TorusCollider final : public DistanceCollider {
 public:
  TorusCollider(const ColliderSpec& s);
  void distance(const Vec3& x, double& phi, Vec3& normal, Mat3& dnormal_dx) const override;

 private:
  Vec3 center_, axis_;
  double major_, tube_;
};

// One collider per spec entry, in order (empty for a scene without colliders).
std::vector<std::unique_ptr<Collider>> make_colliders(const std::vector<ColliderSpec>& specs);

}  // namespace kf
