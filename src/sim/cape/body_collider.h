#pragma once
// The animated character's body as a cloth collider: a repulsive force along the outward normal of the
// closest body point, g(thickness - phi) n (ContactProfile g), when the signed distance phi is below
// `thickness`.
//
// The pose is set from outside once per step (set_pose refits the BVH), so contact() only reads.
//
// Friction (Collider::set_friction) acts against the particle's velocity relative to the body's surface at
// the closest point: the barycentric blend of the vertex velocities set_velocity gives (a still body
// without them). The blend moves with x (the closest point slides on a face or an edge), so the exact
// df/dx holds its derivative too.
#include <atomic>
#include <limits>

#include "sim/character/body_query.h"
#include "sim/cloth/collider.h"

namespace kf {

class BodyCollider final : public Collider {
 public:
  const char* name() const override { return "body"; }
  // triangles: #T by 3 indices into vertex_count body vertices. thickness, search, ramp: metres;
  // stiffness: N/m. A particle more than `search` metres inside the body gets no force (the open shells'
  // inside is a guess far from the surface).
  BodyCollider(const TriangleIndices& triangles, int vertex_count, double thickness, double stiffness,
               double search, double ramp);

  // New body pose: 3n vertex positions, metres, world frame. Allocation-free after the first call.
  void set_pose(const VecX& vertices) { query_.update(vertices); }
  // Body vertex velocities (3n, m/s) of the step, for friction; empty: a still body.
  void set_velocity(const VecX& velocities) { velocity_ = velocities; }

  // f = g n; df/dx = -g' n n^T, plus g dn/dx when `definite` is false and the curvature term is on
  // (dn/dx is zero on a face, sign (I - n n^T) / distance at a vertex and sign (I - n n^T - t t^T) /
  // distance on an edge with tangent t). df/dv = 0.
  bool contact(int n, const Vec3& x, const Vec3& v, bool definite, ContactForce& out) const override;
  Vec3 definite_stiffness_derivative(int n, const Vec3& x, const Vec3& w, const Vec3& c) const override;
  bool friction(int n, const Vec3& x, const Vec3& v, bool exact, ContactForce& out) const override;
  void damping_derivative(int n, const Vec3& x, const Vec3& v, const Vec3& w, const Vec3& c, Vec3& ddx,
                          Vec3& ddv) const override;

  // The curvature term of the exact df/dx (on by default; the exact adjoint needs it). The swap adjoint
  // turns it off: explicit in that adjoint's K^T w and growing as 1/distance near the mesh's edges, it was
  // amplified step after step on the cape blend.
  void set_curvature(bool on) { curvature_ = on; }

  // While counting is on, every contact() that finds a contact adds one to the counter.
  void set_counting(bool on) { counting_ = on; }
  int take_count() { return count_.exchange(0); }
  // While counting is on, also the smallest signed distance (m, negative inside) met within the query
  // radius; taking it resets it to +infinity.
  double take_min_distance() { return min_phi_.exchange(std::numeric_limits<double>::infinity()); }

  const BodyQuery& query() const { return query_; }

 private:
  // The closest body point to x and dn/dx there; false when x is not in contact.
  bool query(const Vec3& x, BodyHit& hit, Mat3& dn) const;
  // The body's velocity at the hit's closest point (m/s) and its derivative in the query point (1/s).
  void surface_velocity(const BodyHit& hit, Vec3& velocity, Mat3& dvelocity_dx) const;

  BodyQuery query_;
  double thickness_;
  ContactProfile profile_;
  double search_;
  VecX velocity_;
  bool curvature_ = true;
  bool counting_ = false;
  mutable std::atomic<int> count_{0};
  mutable std::atomic<double> min_phi_{std::numeric_limits<double>::infinity()};
};

}  // namespace kf
