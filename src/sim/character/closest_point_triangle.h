#pragma once
// Closest point on a triangle to a point, with the feature (face, edge or vertex) it lies on.
#include "core/types.h"

namespace kf {

// Which part of the triangle (a, b, c) holds the closest point. Edges are named by their end vertices.
enum class TriangleFeature : int { kFace, kVertexA, kVertexB, kVertexC, kEdgeAB, kEdgeBC, kEdgeCA };

struct TrianglePoint {
  Vec3 point;                  // closest point, same frame and units as the inputs
  Vec3 barycentric;            // weights of a, b, c (sum 1, each in [0, 1])
  TriangleFeature feature = TriangleFeature::kFace;
};

// Exact region classification (Ericson, Real-Time Collision Detection 5.1.5); a degenerate triangle
// (zero area) still returns a point of the triangle, classified as an edge or vertex.
TrianglePoint closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

}  // namespace kf
