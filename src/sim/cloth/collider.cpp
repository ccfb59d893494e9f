#include "sim/cloth/collider.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>  // unitOrthogonal
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/box_frame.h"
#include "core/overloaded.h"

namespace kf {

void Collider::add_definite_stiffness_derivative(int n, const VecX& x, const VecX& w, const VecX& c, double scale,
                                                 VecX& out) const {
  const int p = int(x.size() / 3);
  tbb::parallel_for(tbb::blocked_range<int>(0, p, 256), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i < r.end(); ++i)
      seg(out, i) += scale * definite_stiffness_derivative(n, seg(x, i), seg(w, i), seg(c, i));
  });
}

bool DistanceCollider::contact(int, const Vec3& x, const Vec3&, bool definite, ContactForce& out) const {
  double phi;
  Vec3 n;
  Mat3 dn;
  distance(x, phi, n, dn);
  if (phi >= thickness_) return false;
  double g, dg, ddg;
  profile_.eval(thickness_ - phi, g, dg, ddg);
  out.f = g * n;
  out.dfdx = -dg * n * n.transpose();
  if (!definite) out.dfdx += g * dn;
  out.dfdv.setZero();
  return true;
}

bool DistanceCollider::friction(int, const Vec3& x, const Vec3& v, bool exact, ContactForce& out) const {
  if (!friction_.on()) return false;
  double phi;
  Vec3 n;
  Mat3 dn;
  distance(x, phi, n, dn);
  if (phi >= thickness_) return false;
  double g, dg, ddg;
  profile_.eval(thickness_ - phi, g, dg, ddg);
  // Limit L = mu g(thickness - phi): dL/dx = -mu g' n. The surface is still: the slip is v itself.
  const FrictionForce fr = friction_force(friction_.mu * g, n, v, friction_.eps);
  out.f = fr.f;
  out.dfdv = fr.damping;
  out.dfdx.setZero();
  out.dfdv_rest.setZero();
  if (exact) {
    out.dfdx = fr.dfdL * (-friction_.mu * dg * n).transpose() + fr.dfdn * dn;
    out.dfdv_rest = fr.dfdu - fr.damping;
  }
  return true;
}

void DistanceCollider::damping_derivative(int, const Vec3& x, const Vec3& v, const Vec3& w, const Vec3& c,
                                          Vec3& ddx, Vec3& ddv) const {
  ddx.setZero();
  ddv.setZero();
  if (!friction_.on()) return;
  double phi;
  Vec3 n;
  Mat3 dn;
  distance(x, phi, n, dn);
  if (phi >= thickness_) return;
  double g, dg, ddg;
  profile_.eval(thickness_ - phi, g, dg, ddg);
  const FrictionDampingDerivative d = friction_damping_derivative(friction_.mu * g, n, v, friction_.eps, w, c);
  ddx = d.dL * (-friction_.mu * dg * n) + dn.transpose() * d.dn;
  ddv = d.du;
}

double DistanceCollider::energy(int, const Vec3& x) const {
  double phi;
  Vec3 n;
  Mat3 dn;
  distance(x, phi, n, dn);
  return profile_.energy(thickness_ - phi);
}

Vec3 DistanceCollider::definite_stiffness_derivative(int, const Vec3& x, const Vec3& w, const Vec3& c) const {
  double phi;
  Vec3 n;
  Mat3 dn;
  distance(x, phi, n, dn);
  if (phi >= thickness_) return Vec3::Zero();
  double g, dg, ddg;
  profile_.eval(thickness_ - phi, g, dg, ddg);
  // w . Kd c = -g'(thickness - phi) (w.n)(c.n); d(thickness - phi)/dx = -n, d(w.n)/dx = dn^T w.
  const double wn = w.dot(n), cn = c.dot(n);
  return ddg * wn * cn * n - dg * (cn * (dn.transpose() * w) + wn * (dn.transpose() * c));
}

GroundCollider::GroundCollider(const GroundShape& s, double thickness, double stiffness, double ramp)
    : DistanceCollider(thickness, stiffness, ramp), point_(s.point), normal_(s.normal.normalized()) {}

void GroundCollider::distance(const Vec3& x, double& phi, Vec3& normal, Mat3& dnormal_dx) const {
  phi = normal_.dot(x - point_);
  normal = normal_;
  dnormal_dx.setZero();
}

SphereCollider::SphereCollider(const SphereShape& s, double thickness, double stiffness, double ramp)
    : DistanceCollider(thickness, stiffness, ramp), center_(s.center), radius_(s.radius) {}

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

TorusCollider::TorusCollider(const TorusShape& s, double thickness, double stiffness, double ramp)
    : DistanceCollider(thickness, stiffness, ramp),
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

CapsuleCollider::CapsuleCollider(const CapsuleShape& s, double thickness, double stiffness, double ramp)
    : DistanceCollider(thickness, stiffness, ramp),
      a_(s.a),
      axis_((s.b - s.a).normalized()),
      length_((s.b - s.a).norm()),
      radius_(s.radius) {}

void CapsuleCollider::distance(const Vec3& x, double& phi, Vec3& normal, Mat3& dnormal_dx) const {
  // The closest point of the segment: q = a + t axis, t clamped to [0, length].
  const double s = axis_.dot(x - a_);
  const bool side = s > 0 && s < length_;  // beside the cylinder, not at a cap
  const Vec3 q = a_ + std::clamp(s, 0.0, length_) * axis_;
  const Vec3 w = x - q;
  const double d = w.norm();
  if (d < 1e-12 * radius_) {  // on the axis every direction across it is as near; pick one so the push is finite
    phi = -radius_;
    normal = axis_.unitOrthogonal();
    dnormal_dx.setZero();
    return;
  }
  phi = d - radius_;
  normal = w / d;
  // dn/dx = (I - n n^T)/d dw/dx, with dw/dx = I - axis axis^T beside the cylinder and I at a cap.
  const Mat3 across = (Mat3::Identity() - normal * normal.transpose()) / d;
  dnormal_dx = side ? Mat3(across * (Mat3::Identity() - axis_ * axis_.transpose())) : across;
}


BoxCollider::BoxCollider(const BoxShape& s, double thickness, double stiffness, double ramp)
    : DistanceCollider(thickness, stiffness, ramp),
      center_(s.center),
      axes_(box_frame(s.u_axis, s.v_axis)),
      half_((0.5 * s.size - Vec3::Constant(s.radius)).cwiseMax(0.0)),
      radius_(s.radius) {}

BoxCollider::BoxCollider(const RectangleShape& s, double thickness, double stiffness, double ramp)
    : DistanceCollider(thickness, stiffness, ramp),
      center_(s.center),
      axes_(box_frame(s.u_axis, s.v_axis)),
      half_(0.5 * s.width, 0.5 * s.height, 0.0),
      radius_(0.0) {}

void BoxCollider::distance(const Vec3& x, double& phi, Vec3& normal, Mat3& dnormal_dx) const {
  const Vec3 q = axes_.transpose() * (x - center_);  // in the box's frame
  const Vec3 w = q - q.cwiseMax(-half_).cwiseMin(half_);  // from the inner box's nearest point
  const double d = w.norm();
  const double scale = std::max(half_.maxCoeff(), radius_);
  if (d <= 1e-12 * scale) {
    // Inside the inner box (a rectangle: in its plane): out through the nearest face; n is constant
    // between the medial planes, where it jumps.
    int k = 0;
    const Vec3 gap = q.cwiseAbs() - half_;
    gap.maxCoeff(&k);
    phi = gap[k] - radius_;
    normal = (q[k] < 0 ? -1.0 : 1.0) * axes_.col(k);
    dnormal_dx.setZero();
    return;
  }
  phi = d - radius_;
  const Vec3 nl = w / d;
  normal = axes_ * nl;
  // dn/dx = R (I - nl nl^T)/d dw/dq R^T, dw/dq = 1 on the axes where q is beyond the inner box, else 0.
  Mat3 dw = Mat3::Zero();
  for (int k = 0; k < 3; ++k) dw(k, k) = std::abs(q[k]) > half_[k] ? 1.0 : 0.0;
  dnormal_dx = axes_ * ((Mat3::Identity() - nl * nl.transpose()) / d * dw) * axes_.transpose();
}

std::vector<std::unique_ptr<Collider>> make_colliders(const std::vector<ColliderSpec>& specs, double ramp_fraction) {
  std::vector<std::unique_ptr<Collider>> out;
  for (const ColliderSpec& s : specs) {
    const double ramp = ramp_fraction * s.thickness;
    out.push_back(std::visit(
        Overloaded{
            [&](const GroundShape& g) -> std::unique_ptr<Collider> {
              return std::make_unique<GroundCollider>(g, s.thickness, s.stiffness, ramp);
            },
            [&](const SphereShape& g) -> std::unique_ptr<Collider> {
              return std::make_unique<SphereCollider>(g, s.thickness, s.stiffness, ramp);
            },
            [&](const TorusShape& g) -> std::unique_ptr<Collider> {
              return std::make_unique<TorusCollider>(g, s.thickness, s.stiffness, ramp);
            },
            [&](const CapsuleShape& g) -> std::unique_ptr<Collider> {
              return std::make_unique<CapsuleCollider>(g, s.thickness, s.stiffness, ramp);
            },
            [&](const BoxShape& g) -> std::unique_ptr<Collider> {
              return std::make_unique<BoxCollider>(g, s.thickness, s.stiffness, ramp);
            },
            [&](const RectangleShape& g) -> std::unique_ptr<Collider> {
              return std::make_unique<BoxCollider>(g, s.thickness, s.stiffness, ramp);
            },
        },
        s.shape));
    out.back()->set_friction({s.friction, s.friction_velocity});
  }
  return out;
}

}  // namespace kf
