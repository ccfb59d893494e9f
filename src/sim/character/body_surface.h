#pragma once
// A posed triangle surface with the normals a closest-point query needs to tell outside from inside.
//
// Inside/outside uses angle-weighted pseudonormals (Baerentzen & Aanaes 2005): the normal of the face,
// edge or vertex that holds the closest point. The sign is exact for a closed, consistently wound mesh;
// the character is three separate open shells (torso, head, legs), so near their rims "inside" is a guess.
#include <array>
#include <optional>
#include <vector>

#include "sim/character/character.h"
#include "sim/character/closest_point_triangle.h"

namespace kf {

// The closest surface point to a query point.
struct BodyHit {
  Vec3 point = Vec3::Zero();        // on the surface, metres, world frame
  int triangle = -1;                // index into the triangle list; -1 when nothing is within the radius
  Vec3 barycentric = Vec3::Zero();  // of `point` in that triangle
  TriangleFeature feature = TriangleFeature::kFace;
  double distance = 0.0;            // |query - point|, metres
  double signed_distance = 0.0;     // negative when the query is behind the surface (inside the body)
  // Outward unit normal = gradient of the signed distance at the query point: (query - point)/distance
  // flipped to point outward; the pseudonormal when the query lies on the surface. A repulsive spring
  // k (thickness - signed_distance) pushes along it; on a face its derivative is zero, on an edge or
  // vertex it is (I - n n^T)/distance.
  Vec3 normal = Vec3::Zero();
  bool found() const { return triangle >= 0; }
};

class BodySurface {
 public:
  // triangles: #T by 3 indices into vertex_count vertices.
  BodySurface(const TriangleIndices& triangles, int vertex_count);

  // Sets the posed vertices (3n, metres) and recomputes face, edge and vertex pseudonormals.
  // Allocation-free after construction.
  void set_vertices(const VecX& x);

  const VecX& vertices() const { return x_; }
  const TriangleIndices& triangles() const { return triangles_; }
  int triangle_count() const { return static_cast<int>(triangles_.rows()); }
  Vec3 face_normal(int f) const { return face_normals_[f]; }

  // Closest point of one triangle to p.
  TrianglePoint closest_on(int triangle, const Vec3& p) const;
  // Fills a hit from a triangle's closest point to p (distance, sign and normal).
  BodyHit make_hit(const Vec3& p, int triangle, const TrianglePoint& tp) const;

  // Reference implementation: tests every triangle; ties keep the lowest triangle index.
  // Returns a hit with triangle = -1 when no surface point is within `radius` metres.
  BodyHit closest_brute_force(const Vec3& p, double radius) const;

 private:
  TriangleIndices triangles_;
  std::vector<std::array<int, 3>> triangle_edges_;  // edge ids of AB, BC, CA
  std::vector<std::array<int, 2>> edge_faces_;      // up to two faces per edge (-1 if boundary)
  VecX x_;
  std::vector<Vec3> face_normals_, edge_normals_, vertex_normals_;
};

}  // namespace kf
