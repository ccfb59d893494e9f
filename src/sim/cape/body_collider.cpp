#include "sim/cape/body_collider.h"

#include <algorithm>

namespace kf {

BodyCollider::BodyCollider(const TriangleIndices& triangles, int vertex_count, double thickness, double stiffness,
                           double search, double ramp)
    : query_(triangles, vertex_count), thickness_(thickness), profile_{stiffness, ramp}, search_(search) {}

bool BodyCollider::query(const Vec3& x, BodyHit& hit, Mat3& dn) const {
  hit = query_.closest(x, std::max(thickness_, search_));
  if (!hit.found()) return false;
  const double phi = hit.signed_distance;
  if (counting_) {
    double m = min_phi_.load(std::memory_order_relaxed);
    while (phi < m && !min_phi_.compare_exchange_weak(m, phi, std::memory_order_relaxed)) {
    }
  }
  if (phi >= thickness_ || phi < -search_) return false;
  dn.setZero();
  if (hit.feature == TriangleFeature::kFace || hit.distance <= 1e-12) return true;
  // The distance to a vertex curves in every direction across n; the distance to an edge's line does
  // not change along the edge, so its tangent drops out too.
  const Vec3& n = hit.normal;
  Mat3 P = Mat3::Identity() - n * n.transpose();
  int a = -1, b = -1;
  switch (hit.feature) {
    case TriangleFeature::kEdgeAB: a = 0, b = 1; break;
    case TriangleFeature::kEdgeBC: a = 1, b = 2; break;
    case TriangleFeature::kEdgeCA: a = 2, b = 0; break;
    default: break;
  }
  if (a >= 0) {
    const auto& surface = query_.surface();
    const VecX& v = surface.vertices();
    const Vec3 t = (seg(v, surface.triangles()(hit.triangle, b)) - seg(v, surface.triangles()(hit.triangle, a))).normalized();
    P -= t * t.transpose();
  }
  dn = (phi < 0 ? -1.0 : 1.0) * P / hit.distance;
  return true;
}

bool BodyCollider::contact(int, const Vec3& x, const Vec3&, bool definite, ContactForce& out) const {
  BodyHit hit;
  Mat3 dn;
  if (!query(x, hit, dn)) return false;
  const Vec3& n = hit.normal;
  double g, dg, ddg;
  profile_.eval(thickness_ - hit.signed_distance, g, dg, ddg);
  out.f = g * n;
  out.dfdx = -dg * n * n.transpose();
  if (!definite && curvature_) out.dfdx += g * dn;
  out.dfdv.setZero();
  if (counting_) count_.fetch_add(1, std::memory_order_relaxed);
  return true;
}

Vec3 BodyCollider::definite_stiffness_derivative(int, const Vec3& x, const Vec3& w, const Vec3& c) const {
  BodyHit hit;
  Mat3 dn;
  if (!query(x, hit, dn)) return Vec3::Zero();
  const Vec3& n = hit.normal;
  double g, dg, ddg;
  profile_.eval(thickness_ - hit.signed_distance, g, dg, ddg);
  const double wn = w.dot(n), cn = c.dot(n);
  return ddg * wn * cn * n - dg * (cn * (dn * w) + wn * (dn * c));  // dn is symmetric
}

}  // namespace kf
