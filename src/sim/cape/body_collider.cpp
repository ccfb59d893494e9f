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

bool BodyCollider::friction(int, const Vec3& x, const Vec3& v, bool exact, ContactForce& out) const {
  BodyHit hit;
  Mat3 dn;
  if (!friction_.on() || !query(x, hit, dn)) return false;
  const Vec3& n = hit.normal;
  double g, dg, ddg;
  profile_.eval(thickness_ - hit.signed_distance, g, dg, ddg);
  Vec3 vb;
  Mat3 dvb;
  surface_velocity(hit, vb, dvb);
  // Limit mu g(thickness - phi), dL/dx = -mu g' n; slip u = v - vb(x).
  const FrictionForce fr = friction_force(friction_.mu * g, n, v - vb, friction_.eps);
  out.f = fr.f;
  out.dfdv = fr.damping;
  out.dfdx.setZero();
  out.dfdv_rest.setZero();
  if (exact) {
    out.dfdv_rest = fr.dfdu - fr.damping;
    out.dfdx = fr.dfdL * (-friction_.mu * dg * n).transpose() - fr.dfdu * dvb;
    if (curvature_) out.dfdx += fr.dfdn * dn;
  }
  return true;
}

void BodyCollider::surface_velocity(const BodyHit& hit, Vec3& velocity, Mat3& dvelocity_dx) const {
  velocity.setZero();
  dvelocity_dx.setZero();
  if (velocity_.size() == 0) return;
  const auto& surface = query_.surface();
  const VecX& x = surface.vertices();
  int id[3];
  for (int k = 0; k < 3; ++k) id[k] = surface.triangles()(hit.triangle, k);
  for (int k = 0; k < 3; ++k) velocity += hit.barycentric[k] * seg(velocity_, id[k]);
  int a = -1, b = -1;
  switch (hit.feature) {
    case TriangleFeature::kFace: {
      // The closest point is x projected on the face's plane: its barycentrics (beta, gamma) along
      // e1 = B - A, e2 = C - A change by (E^T E)^-1 E^T dx.
      Eigen::Matrix<double, 3, 2> E, V;
      for (int k = 0; k < 2; ++k) {
        E.col(k) = seg(x, id[k + 1]) - seg(x, id[0]);
        V.col(k) = seg(velocity_, id[k + 1]) - seg(velocity_, id[0]);
      }
      dvelocity_dx = V * (E.transpose() * E).inverse() * E.transpose();
      return;
    }
    case TriangleFeature::kEdgeAB: a = 0, b = 1; break;
    case TriangleFeature::kEdgeBC: a = 1, b = 2; break;
    case TriangleFeature::kEdgeCA: a = 2, b = 0; break;
    default: return;  // at a vertex the closest point stays put
  }
  // On an edge the closest point slides along it by e e^T dx / |e|^2.
  const Vec3 e = seg(x, id[b]) - seg(x, id[a]);
  dvelocity_dx = (seg(velocity_, id[b]) - seg(velocity_, id[a])) * e.transpose() / e.squaredNorm();
}

void BodyCollider::damping_derivative(int, const Vec3& x, const Vec3& v, const Vec3& w, const Vec3& c, Vec3& ddx,
                                      Vec3& ddv) const {
  ddx.setZero();
  ddv.setZero();
  BodyHit hit;
  Mat3 dn;
  if (!friction_.on() || !query(x, hit, dn)) return;
  const Vec3& n = hit.normal;
  double g, dg, ddg;
  profile_.eval(thickness_ - hit.signed_distance, g, dg, ddg);
  Vec3 vb;
  Mat3 dvb;
  surface_velocity(hit, vb, dvb);
  const FrictionDampingDerivative d = friction_damping_derivative(friction_.mu * g, n, v - vb, friction_.eps, w, c);
  ddx = d.dL * (-friction_.mu * dg * n) - dvb.transpose() * d.du;
  if (curvature_) ddx += dn * d.dn;  // dn is symmetric
  ddv = d.du;
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
