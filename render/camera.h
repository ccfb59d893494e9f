#pragma once
// A pinhole camera and its automatic placement around a trajectory's bounding box.
#include "core/types.h"
#include "render/camera_choice.h"
#include "scene/render_spec.h"

namespace kf::render {

struct Bounds {
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  void add(const Vec3& p) { lo = lo.cwiseMin(p); hi = hi.cwiseMax(p); }
  bool empty() const { return lo.x() > hi.x(); }
  Vec3 center() const { return 0.5 * (lo + hi); }
  double radius() const { return 0.5 * (hi - lo).norm(); }  // metres
};

struct Camera {
  Vec3 eye, target, up;  // metres, world frame; up need not be orthogonal to the view
  double fov = 40.0;     // vertical field of view, degrees
  double aspect = 4.0 / 3.0;  // width / height

  // Orthonormal frame: forward (towards target), right, true up.
  void basis(Vec3& forward, Vec3& right, Vec3& true_up) const;
  // Column-major 4x4 view and projection matrices (OpenGL conventions), near/far in metres.
  Eigen::Matrix4d view() const;
  Eigen::Matrix4d projection(double near, double far) const;
  // Same camera orbited about the world Y axis through `target` by `radians`.
  Camera orbited(double radians) const;
};

// The camera `choice` gives (--camera, or a named view framing `bounds`), else the scene's camera if it
// states one, else one framing `bounds` (flocks from high above, cloth at three quarters; `is_flock` picks
// the direction). A framing camera looks at the box's centre from far enough that all eight corners of
// `bounds` (every particle, keyframe target and collider) project inside the image.
Camera make_camera(const RenderSpec& spec, const Bounds& bounds, bool is_flock, int width, int height,
                   const CameraChoice& choice = {});

// The distance from `bounds`' centre along `dir` (unit, toward the eye) at which every corner of `bounds`
// lies inside a `fov`-degree (vertical) view of `aspect` = width / height, filling at most `fill` of each
// half-extent.
double framing_distance(const Bounds& bounds, const Vec3& dir, const Vec3& up, double fov, double aspect,
                        double fill);

}  // namespace kf::render
