#include "sim/character/body_surface.h"

#include <cmath>
#include <limits>
#include <map>

namespace kf {

BodySurface::BodySurface(const TriangleIndices& triangles, int vertex_count)
    : triangles_(triangles),
      x_(VecX::Zero(3 * vertex_count)),
      face_normals_(triangles.rows(), Vec3::Zero()),
      vertex_normals_(vertex_count, Vec3::Zero()) {
  std::map<std::pair<int, int>, int> edge_id;
  triangle_edges_.resize(triangles.rows());
  for (int f = 0; f < triangles.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = triangles(f, k), b = triangles(f, (k + 1) % 3);
      const auto key = std::minmax(a, b);
      auto [it, inserted] = edge_id.emplace(std::pair<int, int>(key.first, key.second), static_cast<int>(edge_faces_.size()));
      if (inserted) edge_faces_.push_back({f, -1});
      else if (edge_faces_[it->second][1] < 0) edge_faces_[it->second][1] = f;  // a third face is ignored
      triangle_edges_[f][k] = it->second;
    }
  }
  edge_normals_.assign(edge_faces_.size(), Vec3::Zero());
}

void BodySurface::set_vertices(const VecX& x) {
  x_ = x;
  for (auto& n : vertex_normals_) n.setZero();
  for (int f = 0; f < triangle_count(); ++f) {
    const int i[3] = {triangles_(f, 0), triangles_(f, 1), triangles_(f, 2)};
    const Vec3 p[3] = {seg(x_, i[0]), seg(x_, i[1]), seg(x_, i[2])};
    const Vec3 n = (p[1] - p[0]).cross(p[2] - p[0]);
    const double len = n.norm();
    face_normals_[f] = len > 0.0 ? Vec3(n / len) : Vec3::Zero();
    for (int k = 0; k < 3; ++k) {
      const Vec3 e1 = p[(k + 1) % 3] - p[k], e2 = p[(k + 2) % 3] - p[k];
      const double angle = std::atan2(e1.cross(e2).norm(), e1.dot(e2));
      vertex_normals_[i[k]] += angle * face_normals_[f];
    }
  }
  for (size_t e = 0; e < edge_faces_.size(); ++e) {
    edge_normals_[e] = face_normals_[edge_faces_[e][0]];
    if (edge_faces_[e][1] >= 0) edge_normals_[e] += face_normals_[edge_faces_[e][1]];
  }
  // Pseudonormals only give a sign; they are normalised so they can also serve as a fallback direction.
  for (auto& n : edge_normals_) n.normalize();
  for (auto& n : vertex_normals_) n.normalize();
}

TrianglePoint BodySurface::closest_on(int f, const Vec3& p) const {
  return closest_point_on_triangle(p, seg(x_, triangles_(f, 0)), seg(x_, triangles_(f, 1)),
                                   seg(x_, triangles_(f, 2)));
}

BodyHit BodySurface::make_hit(const Vec3& p, int f, const TrianglePoint& tp) const {
  using F = TriangleFeature;
  Vec3 pseudo;
  switch (tp.feature) {
    case F::kFace: pseudo = face_normals_[f]; break;
    case F::kVertexA: pseudo = vertex_normals_[triangles_(f, 0)]; break;
    case F::kVertexB: pseudo = vertex_normals_[triangles_(f, 1)]; break;
    case F::kVertexC: pseudo = vertex_normals_[triangles_(f, 2)]; break;
    case F::kEdgeAB: pseudo = edge_normals_[triangle_edges_[f][0]]; break;
    case F::kEdgeBC: pseudo = edge_normals_[triangle_edges_[f][1]]; break;
    case F::kEdgeCA: pseudo = edge_normals_[triangle_edges_[f][2]]; break;
  }
  BodyHit hit;
  hit.point = tp.point;
  hit.triangle = f;
  hit.barycentric = tp.barycentric;
  hit.feature = tp.feature;
  const Vec3 d = p - tp.point;
  hit.distance = d.norm();
  const double sign = d.dot(pseudo) < 0.0 ? -1.0 : 1.0;
  hit.signed_distance = sign * hit.distance;
  // Below ~1e-12 m the direction p - point is round-off; the surface's own normal is the limit.
  hit.normal = hit.distance > 1e-12 ? Vec3(sign * d / hit.distance) : pseudo;
  return hit;
}

BodyHit BodySurface::closest_brute_force(const Vec3& p, double radius) const {
  int best = -1;
  TrianglePoint best_tp;
  double best_d2 = std::numeric_limits<double>::infinity();
  for (int f = 0; f < triangle_count(); ++f) {
    const TrianglePoint tp = closest_on(f, p);
    const double d2 = (p - tp.point).squaredNorm();
    if (d2 < best_d2) best_d2 = d2, best = f, best_tp = tp;
  }
  if (best < 0 || best_d2 > radius * radius) return {};
  return make_hit(p, best, best_tp);
}

}  // namespace kf
