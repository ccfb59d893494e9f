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

Camera make_camera(const RenderSpec& spec, const Bounds& bounds, bool is_flock, int width, int height) {
  Camera c;
  c.aspect = double(width) / double(height);
  if (spec.has_camera) {
    c.eye = spec.camera.eye;
    c.target = spec.camera.target;
    c.up = spec.camera.up;
    c.fov = spec.camera.fov;
    return c;
  }
  c.fov = spec.fov;
  c.up = Vec3::UnitY();
  const Vec3 center = bounds.empty() ? Vec3::Zero() : bounds.center();
  const double radius = std::max(bounds.empty() ? 1.0 : bounds.radius(), 0.25);
  // Flocks are flat: a steep view shows their shapes; cloth reads best from the front, a little above.
  const Vec3 dir = is_flock ? Vec3(0.0, 1.0, 0.62).normalized() : Vec3(0.55, 0.42, 1.0).normalized();
  const double half = 0.5 * c.fov * M_PI / 180.0;
  const double half_narrow = std::min(half, std::atan(std::tan(half) * c.aspect));
  // A flat box seen from above needs less room than its bounding sphere.
  const double fill = is_flock ? 0.85 : 1.0;
  const double dist = fill * radius / std::sin(half_narrow);
  c.target = center;
  c.eye = center + dir * dist;
  return c;
}

}  // namespace kf::render
