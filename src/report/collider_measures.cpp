#include "report/collider_measures.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/overloaded.h"
#include "opt/keyframes/keyframe_common.h"
#include "sim/cloth/collider.h"

namespace kf {

namespace {

// How far a free sheet turned over: the angle of its normal (from the corner diagonals) from frame 0's.
nlohmann::json sheet_measures(const ClothSpec& cloth, const Trajectory& t) {
  const int a = 0, b = cloth.nx - 1, c = (cloth.ny - 1) * cloth.nx, d = cloth.nx * cloth.ny - 1;
  auto normal = [&](const VecX& x) {
    const Vec3 n = (seg(x, d) - seg(x, a)).cross(seg(x, c) - seg(x, b));
    return n.norm() > 0 ? Vec3(n.normalized()) : Vec3::UnitY();
  };
  const Vec3 n0 = normal(t.x[0]);
  auto degrees = [&](const VecX& x) { return std::acos(std::clamp(n0.dot(normal(x)), -1.0, 1.0)) * 180.0 / M_PI; };
  double most = 0;
  for (int f = 0; f < t.frames(); ++f) most = std::max(most, degrees(t.x[size_t(f)]));
  return {{"type", "sheet"}, {"flip_degrees", most}, {"flip_degrees_at_end", degrees(t.x.back())}};
}

// A collider's own measures over a run (null for shapes that have none): a ring's crossing, a free sheet's
// landing on the ground.
nlohmann::json collider_measures(const ClothSpec& cloth, const ColliderSpec& c, const Trajectory& t) {
  return std::visit(Overloaded{
                        [&](const TorusShape& torus) { return ring_measures(torus, t); },
                        [&](const GroundShape& ground) {
                          return cloth.pins.empty() ? ground_measures(ground, c.thickness, t) : nlohmann::json();
                        },
                        [](const SphereShape&) { return nlohmann::json(); },
                        [](const CapsuleShape&) { return nlohmann::json(); },
                        [&](const BoxShape&) { return surface_measures(c, t); },
                        [&](const RectangleShape&) { return surface_measures(c, t); },
                    },
                    c.shape);
}

}  // namespace

void add_cloth_measures(const ClothSpec& cloth, const Trajectory& t, nlohmann::json& out) {
  if (cloth.pins.empty() && !cloth.mesh) out.push_back(sheet_measures(cloth, t));
  for (size_t k = 0; k < cloth.colliders.size(); ++k) {
    nlohmann::json m = collider_measures(cloth, cloth.colliders[k], t);
    if (m.is_null()) continue;
    m["collider"] = int(k);
    out.push_back(m);
  }
}

nlohmann::json ground_measures(const GroundShape& ground, double thickness, const Trajectory& t) {
  const Vec3 n = ground.normal.normalized();
  const VecX& x = t.x.back();
  double lowest = std::numeric_limits<double>::infinity(), sum = 0;
  const int p = int(x.size() / 3);
  for (int i = 0; i < p; ++i) {
    const double h = n.dot(seg(x, i) - ground.point);
    lowest = std::min(lowest, h);
    sum += h;
  }
  // Resting on it: within two contact thicknesses (the contact springs hold a sheet about one above it).
  return {{"type", "ground"},
          {"lowest_at_end", lowest},
          {"mean_height_at_end", sum / std::max(1, p)},
          {"on_ground_at_end", lowest <= 2 * thickness}};
}

nlohmann::json surface_measures(const ColliderSpec& collider, const Trajectory& t) {
  const std::vector<std::unique_ptr<Collider>> made = make_colliders({collider}, 0.0);
  const auto& surface = dynamic_cast<const DistanceCollider&>(*made.front());
  double min_phi = std::numeric_limits<double>::infinity();
  int min_frame = 0, touching = 0;
  for (int f = 0; f < t.frames(); ++f) {
    const VecX& x = t.x[size_t(f)];
    for (int i = 0; i < x.size() / 3; ++i) {
      double phi;
      Vec3 n;
      Mat3 dn;
      surface.distance(seg(x, i), phi, n, dn);
      if (phi < min_phi) {
        min_phi = phi;
        min_frame = f;
      }
      if (f + 1 == t.frames() && phi <= 2 * collider.thickness) ++touching;
    }
  }
  return {{"type", type_name(collider)},
          {"min_distance", min_phi},
          {"min_distance_frame", min_frame},
          {"touching_at_end", touching}};
}

namespace {

// The smallest signed distance to the ring along each particle's straight path from one frame to the next
// (at most `so_far`). The simulation's contacts act only at steps, so a fast particle could pass through
// the tube unseen by the frames. Paths whose whole length is farther from the surface than their half length
// cannot come closer than that; the others are sampled at `spacing` (m).
double min_distance_between_frames(const TorusCollider& ring, const Trajectory& t, double spacing, double so_far) {
  double min_between = so_far;
  for (int f = 0; f + 1 < t.frames(); ++f)
    for (int i = 0; i < t.x[size_t(f)].size() / 3; ++i) {
      const Vec3 a = seg(t.x[size_t(f)], i), b = seg(t.x[size_t(f) + 1], i);
      double phi;
      Vec3 n;
      Mat3 dn;
      ring.distance(0.5 * (a + b), phi, n, dn);
      const double half = 0.5 * (b - a).norm();
      if (phi - half >= min_between) continue;  // cannot lower the minimum
      const int samples = 1 + int(std::ceil(2 * half / spacing));
      for (int k = 0; k <= samples; ++k) {
        ring.distance(a + (b - a) * (double(k) / samples), phi, n, dn);
        min_between = std::min(min_between, phi);
      }
    }
  return min_between;
}

}  // namespace

nlohmann::json ring_measures(const TorusShape& torus, const Trajectory& t) {
  const TorusCollider ring(torus, 0.0, 0.0, 0.0);  // distances only
  const Vec3 axis = torus.axis.normalized();
  const double inner = torus.radius - torus.tube_radius;
  double min_phi = std::numeric_limits<double>::infinity();
  double min_axis = std::numeric_limits<double>::infinity();
  int crossings = 0;
  Vec3 prev = Vec3::Zero();
  for (int f = 0; f < t.frames(); ++f) {
    const VecX& x = t.x[f];
    for (int i = 0; i < x.size() / 3; ++i) {
      double phi;
      Vec3 n;
      Mat3 dn;
      ring.distance(seg(x, i), phi, n, dn);
      min_phi = std::min(min_phi, phi);
    }
    const Vec3 com = mean_of(x, {});
    if (f > 0) {
      const double a0 = axis.dot(prev - torus.center), a1 = axis.dot(com - torus.center);
      if ((a0 < 0) != (a1 < 0)) {
        // Where the straight segment between the two frames' centres of mass meets the ring's plane.
        const double s = a0 / (a0 - a1);
        const Vec3 d = prev + s * (com - prev) - torus.center;
        min_axis = std::min(min_axis, (d - axis.dot(d) * axis).norm());
        ++crossings;
      }
    }
    prev = com;
  }
  const double min_between = min_distance_between_frames(ring, t, 0.25 * torus.tube_radius, min_phi);
  // Where the sheet ends, along the ring's axis from its plane, in the direction it crossed (positive: beyond).
  const Vec3 end_com = mean_of(t.x.back(), {});
  const double start_side = axis.dot(mean_of(t.x.front(), {}) - torus.center);
  nlohmann::json m = {{"type", "ring"}};
  m["crossings"] = crossings;
  m["inner_radius"] = inner;
  m["through_ring"] = crossings > 0 && min_axis < inner;
  m["min_distance_to_ring_axis_when_crossing"] = crossings > 0 ? nlohmann::json(min_axis) : nlohmann::json();
  m["min_signed_distance"] = min_phi;
  m["min_signed_distance_between_frames"] = min_between;
  m["penetration_free"] = min_phi >= 0 && min_between >= 0;
  m["end_beyond_ring_plane"] = (start_side < 0 ? 1.0 : -1.0) * axis.dot(end_com - torus.center);
  return m;
}

}  // namespace kf
