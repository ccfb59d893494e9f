#include "sim/cloth/collider.h"

#include <cmath>
#include <stdexcept>

namespace kf {

bool DistanceCollider::contact(int, const Vec3& x, const Vec3&, bool definite, ContactForce& out) const {
  double phi;
  Vec3 n;
  Mat3 dn;
  distance(x, phi, n, dn);
  if (phi >= thickness_) return false;
  const double depth = thickness_ - phi;
  out.f = stiffness_ * depth * n;
  out.dfdx = -stiffness_ * n * n.transpose();
  if (!definite) out.dfdx += stiffness_ * depth * dn;
  out.dfdv.setZero();
  return true;
}

GroundCollider::GroundCollider(const ColliderSpec& s)
    : DistanceCollider(s.thickness, s.stiffness), point_(s.center), normal_(s.axis.normalized()) {}

void GroundCollider::distance(const Vec3& x, double& phi, Vec3& normal, Mat3& dnormal_dx) const {
  phi = normal_.dot(x - point_);
  normal = normal_;
  dnormal_dx.setZero();
}

SphereCollider::SphereCollider(const ColliderSpec& s)
    : DistanceCollider(s.thickness, s.stiffness), center_(s.center), radius_(s.radius) {}

void SphereCollider::distance(const Vec3& x, double& phi, Vec3& normal, Mat3& dnormal_dx) const {
  const Vec3 d = x - center_;
  const double r = d.norm();
  if (r < 1e-12 * radius_) {  // at the centre any direction is as good as another
    phi = -radius_;
    normal = Vec3::UnitY();
    dnormal_dx.setZero();
    return;
  }
  phi = r - radius_;
  normal = d / r;
  dnormal_dx = (Mat3::Identity() - normal * normal.transpose()) / r;
}

TorusCollider::TorusCollider(const ColliderSpec& s)
    : DistanceCollider(s.thickness, s.stiffness),
      center_(s.center),
      axis_(s.axis.normalized()),
      major_(s.radius),
      tube_(s.tube_radius) {}

void TorusCollider::distance(const Vec3& x, double& phi, Vec3& normal, Mat3& dnormal_dx) const {
  const Vec3 p = x - center_;
  const Vec3 q = p - axis_.dot(p) * axis_;  // in the ring's plane
  const double rho = q.norm();
  const Mat3 plane = Mat3::Identity() - axis_ * axis_.transpose();
  Vec3 radial;
  Mat3 dradial;  // d(radial)/dx
  if (rho < 1e-12 * major_) {
    // On the axis every point of the ring is equally close; pick one so the force stays finite.
    radial = plane * (std::abs(axis_.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY());
    radial.normalize();
    dradial.setZero();
  } else {
    radial = q / rho;
    dradial = (plane - radial * radial.transpose()) / rho;
  }
  const Vec3 w = p - major_ * radial;  // from the nearest point of the tube's centre line
  const double d = w.norm();
  if (d < 1e-12 * tube_) {
    phi = -tube_;
    normal = axis_;
    dnormal_dx.setZero();
    return;
  }
  phi = d - tube_;
  normal = w / d;
  const Mat3 dw = Mat3::Identity() - major_ * dradial;
  dnormal_dx = (Mat3::Identity() - normal * normal.transpose()) / d * dw;
}

std::vector<std::unique_ptr<Collider>> make_colliders(const std::vector<ColliderSpec>& specs) {
  std::vector<std::unique_ptr<Collider>> out;
  for (const ColliderSpec& s : specs) {
    if (s.type == "ground") out.push_back(std::make_unique<GroundCollider>(s));
    else if (s.type == "sphere") out.push_back(std::make_unique<SphereCollider>(s));
    else if (s.type == "torus") out.push_back(std::make_unique<TorusCollider>(s));
    else throw std::invalid_argument("unknown collider type \"" + s.type + "\"");
  }
  return out;
}

}  // namespace kf
