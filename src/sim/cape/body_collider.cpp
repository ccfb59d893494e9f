#include "sim/cape/body_collider.h"

#include <algorithm>

namespace kf {

BodyCollider::BodyCollider(const TriangleIndices& triangles, int vertex_count, double thickness, double stiffness,
                           double search)
    : query_(triangles, vertex_count), thickness_(thickness), stiffness_(stiffness), search_(search) {}

bool BodyCollider::contact(int, const Vec3& x, const Vec3&, bool definite, ContactForce& out) const {
  const BodyHit hit = query_.closest(x, std::max(thickness_, search_));
  if (!hit.found()) return false;
  const double phi = hit.signed_distance;
  if (counting_) {
    double m = min_phi_.load(std::memory_order_relaxed);
    while (phi < m && !min_phi_.compare_exchange_weak(m, phi, std::memory_order_relaxed)) {
    }
  }
  if (phi >= thickness_ || phi < -search_) return false;
  const Vec3& n = hit.normal;
  const double depth = thickness_ - phi;
  out.f = stiffness_ * depth * n;
  out.dfdx = -stiffness_ * n * n.transpose();
  if (!definite && curvature_ && hit.feature != TriangleFeature::kFace && hit.distance > 1e-12) {
    const double sign = phi < 0 ? -1.0 : 1.0;
    out.dfdx += stiffness_ * depth * sign * (Mat3::Identity() - n * n.transpose()) / hit.distance;
  }
  out.dfdv.setZero();
  if (counting_) count_.fetch_add(1, std::memory_order_relaxed);
  return true;
}

}  // namespace kf
