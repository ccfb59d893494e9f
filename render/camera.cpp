#include "render/camera.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace kf::render {

void Camera::basis(Vec3& forward, Vec3& right, Vec3& true_up) const {
  forward = (target - eye).normalized();
  right = forward.cross(up).normalized();
  true_up = right.cross(forward);
}

Eigen::Matrix4d Camera::view() const {
  Vec3 f, r, u;
  basis(f, r, u);
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.block<1, 3>(0, 0) = r.transpose();
  m.block<1, 3>(1, 0) = u.transpose();
  m.block<1, 3>(2, 0) = -f.transpose();
  m(0, 3) = -r.dot(eye);
  m(1, 3) = -u.dot(eye);
  m(2, 3) = f.dot(eye);
  return m;
}

Eigen::Matrix4d Camera::projection(double near, double far) const {
  const double t = 1.0 / std::tan(0.5 * fov * M_PI / 180.0);
  Eigen::Matrix4d p = Eigen::Matrix4d::Zero();
  p(0, 0) = t / aspect;
  p(1, 1) = t;
  p(2, 2) = (far + near) / (near - far);
  p(2, 3) = 2.0 * far * near / (near - far);
  p(3, 2) = -1.0;
  return p;
}

Camera Camera::orbited(double radians) const {
  Camera c = *this;
  const Eigen::AngleAxisd rot(radians, Vec3::UnitY());
  c.eye = target + rot * (eye - target);
  c.up = rot * up;
  return c;
}

double framing_distance(const Bounds& bounds, const Vec3& dir, const Vec3& up, double fov, double aspect,
                        double fill) {
  Camera probe;
  probe.target = bounds.center();
  probe.eye = probe.target + dir;
  probe.up = up;
  Vec3 f, r, u;
  probe.basis(f, r, u);
  const double ty = std::tan(0.5 * fov * M_PI / 180.0) * fill, tx = ty * aspect;
  double d = 0.0;
  for (int k = 0; k < 8; ++k) {
    const Vec3 corner((k & 1) ? bounds.hi.x() : bounds.lo.x(), (k & 2) ? bounds.hi.y() : bounds.lo.y(),
                      (k & 4) ? bounds.hi.z() : bounds.lo.z());
    const Vec3 q = corner - probe.target;
    // A corner at depth d + f.q in front of the eye is inside when |r.q| <= tx (d + f.q), likewise up.
    d = std::max({d, std::abs(r.dot(q)) / tx - f.dot(q), std::abs(u.dot(q)) / ty - f.dot(q)});
  }
  return d;
}

Camera make_camera(const RenderSpec& spec, const Bounds& bounds, bool is_flock, int width, int height,
                   const CameraChoice& choice) {
  Camera c;
  c.aspect = double(width) / double(height);
  if (choice.camera || (spec.has_camera && !choice.view)) {
    const CameraSpec& s = choice.camera ? *choice.camera : spec.camera;
    c.eye = s.eye;
    c.target = s.target;
    c.up = s.up;
    c.fov = s.fov > 0.0 ? s.fov : spec.fov;
    return c;
  }
  c.fov = spec.fov;
  c.up = Vec3::UnitY();
  const Bounds box = bounds.empty() ? Bounds{Vec3::Constant(-0.5), Vec3::Constant(0.5)} : bounds;
  const Vec3 center = box.center();
  const double radius = std::max(box.radius(), 0.25);
  // Flocks are flat: a steep view shows their shapes; cloth reads best from the front, a little above.
  Vec3 dir = is_flock ? Vec3(0.0, 1.0, 0.62).normalized() : Vec3(0.55, 0.42, 1.0).normalized();
  double dist = 0.0;
  if (choice.view) {
    dir = view_direction(*choice.view, c.up);
  } else {
    // The bounding sphere's fit (a flat box seen from above needs less room than its sphere) unless a
    // corner would fall outside it.
    const double half = 0.5 * c.fov * M_PI / 180.0;
    const double half_narrow = std::min(half, std::atan(std::tan(half) * c.aspect));
    dist = (is_flock ? 0.85 : 1.0) * radius / std::sin(half_narrow);
  }
  dist = std::max({dist, framing_distance(box, dir, c.up, c.fov, c.aspect, 0.92), 0.5 * radius});
  c.target = center;
  c.eye = center + dir * dist;
  return c;
}

}  // namespace kf::render
