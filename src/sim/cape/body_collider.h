#pragma once
// The animated character's body as a cloth collider: a repulsive spring along the outward normal of the
// closest body point, k (thickness - phi) n, when the signed distance phi is below `thickness`.
//
// The pose is set from outside once per step (set_pose refits the BVH), so contact() only reads.
#include <atomic>
#include <limits>

#include "sim/character/body_query.h"
#include "sim/cloth/collider.h"

namespace kf {

class BodyCollider final : public Collider {
 public:
  // triangles: #T by 3 indices into vertex_count body vertices. thickness, search: metres; stiffness: N/m.
  // A particle more than `search` metres inside the body gets no force (the open shells' inside is a guess
  // far from the surface).
  BodyCollider(const TriangleIndices& triangles, int vertex_count, double thickness, double stiffness,
               double search);

  // New body pose: 3n vertex positions, metres, world frame. Allocation-free after the first call.
  void set_pose(const VecX& vertices) { query_.update(vertices); }

  // f = k (thickness - phi) n; df/dx = -k n n^T, plus k (thickness - phi) dn/dx when `definite` is false
  // and the curvature term is on (dn/dx is zero on a face and sign (I - n n^T) / distance on an edge or a
  // vertex). df/dv = 0.
  bool contact(int n, const Vec3& x, const Vec3& v, bool definite, ContactForce& out) const override;

  // The curvature term (off by default). Near the mesh's edges and vertices it grows as 1/distance and,
  // being explicit in the cloth adjoint's K^T w, it is amplified step after step: on the cape blend it
  // drove the gradient to 1e30 (cosine against finite differences -0.17); without it the adjoint uses the
  // same contact stiffness as the implicit matrix and agrees with the differences (cosine 0.97).
  void set_curvature(bool on) { curvature_ = on; }

  // While counting is on, every contact() that finds a contact adds one to the counter.
  void set_counting(bool on) { counting_ = on; }
  int take_count() { return count_.exchange(0); }
  // While counting is on, also the smallest signed distance (m, negative inside) met within the query
  // radius; taking it resets it to +infinity.
  double take_min_distance() { return min_phi_.exchange(std::numeric_limits<double>::infinity()); }

  const BodyQuery& query() const { return query_; }

 private:
  BodyQuery query_;
  double thickness_, stiffness_, search_;
  bool curvature_ = false;
  bool counting_ = false;
  mutable std::atomic<int> count_{0};
  mutable std::atomic<double> min_phi_{std::numeric_limits<double>::infinity()};
};

}  // namespace kf
