#pragma once
// Closest points on a moving body mesh (the animated character) with an Embree 3 BVH refit per pose.
//
// Typical use per cloth step: character.pose(t, x); query.update(x); query.closest_batch(particles, r, hits).
#include <vector>

#include "sim/character/body_surface.h"
#include "core/embree_handles.h"

namespace kf {

class BodyQuery {
 public:
  // triangles: #T by 3 indices into vertex_count vertices. The BVH is built on the first update().
  BodyQuery(const TriangleIndices& triangles, int vertex_count);

  // New pose: x = 3n vertex positions (metres). Refits the BVH (topology is fixed) and recomputes
  // the normals. Allocation-free after the first call.
  void update(const VecX& x);

  // Closest body point to p within `radius` metres (hit.triangle = -1 when there is none).
  // Thread-safe between updates.
  BodyHit closest(const Vec3& p, double radius) const;
  // One query per point of `points` (3m entries); hits gets m entries. Runs in parallel with TBB, each
  // point written by one task only, so the result does not depend on the thread count.
  void closest_batch(const VecX& points, double radius, std::vector<BodyHit>& hits) const;

  const BodySurface& surface() const { return surface_; }

 private:
  BodySurface surface_;
  EmbreeDevice device_;
  EmbreeScene scene_;
  RTCGeometry geometry_ = nullptr;  // owned by scene_
  float* vertex_buffer_ = nullptr;  // owned by geometry_: n x 3 floats (BVH bounds only)
  bool built_ = false;
};

}  // namespace kf
