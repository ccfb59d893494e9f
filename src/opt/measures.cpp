#include "opt/measures.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "opt/objective_terms.h"
#include "sim/cloth/collider.h"

namespace kf {

std::vector<double> nearest_neighbour_spacing(const VecX& x) {
  const int p = int(x.size() / 3);
  std::vector<double> nn(p, std::numeric_limits<double>::infinity());
  for (int i = 0; i < p; ++i)
    for (int j = i + 1; j < p; ++j) {
      const double d = std::hypot(x[3 * i] - x[3 * j], x[3 * i + 2] - x[3 * j + 2]);
      nn[i] = std::min(nn[i], d);
      nn[j] = std::min(nn[j], d);
    }
  return nn;
}

namespace {

Vec3 mean_of(const VecX& x, const std::vector<int>& ids) {
  Vec3 m = Vec3::Zero();
  if (ids.empty()) {
    for (int i = 0; i < x.size() / 3; ++i) m += seg(x, i);
    return m / double(x.size() / 3);
  }
  for (int i : ids) m += seg(x, i);
  return m / double(ids.size());
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

}  // namespace

nlohmann::json figure_measures(const Scene& scene, const Trajectory& t) {
  nlohmann::json out = nlohmann::json::array();
  const int last = t.frames() - 1;
  for (const auto& o : scene.objectives) {
    const int f = std::min(o.frame, last);
    const VecX& x = t.x[f];
    nlohmann::json m = {{"type", o.type}, {"frame", o.frame}};
    if (o.type == "shape") {
      int inside = 0;
      const int p = int(x.size() / 3);
      for (int i = 0; i < p; ++i) inside += polygon_contains(o.polygon, Vec2(x[3 * i], x[3 * i + 2]));
      const auto nn = nearest_neighbour_spacing(x);
      m["inside_fraction"] = double(inside) / p;
      m["min_spacing"] = *std::min_element(nn.begin(), nn.end());
      m["median_spacing"] = median(nn);
    } else if (o.type == "center_of_mass") {
      // Path: the start's centre of mass, then every centre-of-mass target in frame order.
      std::vector<std::pair<int, Vec3>> pts{{0, mean_of(t.x[0], o.particles)}};
      for (const auto& q : scene.objectives)
        if (q.type == "center_of_mass") pts.emplace_back(q.frame, q.targets[0]);
      std::stable_sort(pts.begin(), pts.end(), [](auto& a, auto& b) { return a.first < b.first; });
      double length = 0;
      for (size_t k = 1; k < pts.size(); ++k) length += (pts[k].second - pts[k - 1].second).norm();
      const double err = (mean_of(x, o.particles) - o.targets[0]).norm();
      m["error"] = err;
      m["path_length"] = length;
      m["error_over_path"] = length > 0 ? err / length : 0.0;
    } else if (o.type == "position" && scene.flock && o.particles.size() == 1) {
      const int a = o.particles[0];
      Vec3 heading = mean_of(t.x[f], {}) - mean_of(t.x[0], {});
      if (heading.norm() < 1e-12) heading = Vec3::UnitX();
      heading.normalize();
      auto rank = [&](const VecX& s) {
        const double mine = seg(s, a).dot(heading);
        int r = 0;
        for (int i = 0; i < s.size() / 3; ++i) r += (i != a && seg(s, i).dot(heading) < mine);
        return r;
      };
      const int p = int(x.size() / 3);
      const int r0 = rank(t.x[0]), r1 = rank(x);
      m["rank_at_start"] = r0;
      m["rank_at_end"] = r1;
      m["last_at_start"] = r0 == 0;
      m["first_at_end"] = r1 == p - 1;
      m["rms_error"] = (seg(x, a) - o.targets[0]).norm();
    } else if (o.type == "position" || o.type == "velocity") {
      const VecX& q = o.type == "position" ? x : t.v[f];
      double sum = 0;
      const int n = o.particles.empty() ? int(q.size() / 3) : int(o.particles.size());
      for (int k = 0; k < n; ++k) {
        const int i = o.particles.empty() ? k : o.particles[k];
        sum += (seg(q, i) - o.targets[o.targets.size() == 1 ? 0 : k]).squaredNorm();
      }
      m["rms_error"] = std::sqrt(sum / n);
      if (scene.cloth && o.type == "position") {
        const double width = (seg(t.x[0], scene.cloth->nx - 1) - seg(t.x[0], 0)).norm();
        m["rms_over_width"] = width > 0 ? std::sqrt(sum / n) / width : 0.0;
      }
    } else if (o.type == "arch") {
      double sum = 0;
      const int p = int(x.size() / 3);
      for (int i = 0; i < p; ++i) {
        const Vec3 d = seg(x, i) - o.axis_point;
        const double e = (d - d.dot(o.axis) * o.axis).norm() - o.radius;
        sum += e * e;
      }
      const int nx = scene.cloth ? scene.cloth->nx : 1;
      const double width = (seg(t.x[0], nx - 1) - seg(t.x[0], 0)).norm();
      m["rms_distance"] = std::sqrt(sum / p);
      m["width"] = width;
      m["rms_over_width"] = width > 0 ? std::sqrt(sum / p) / width : 0.0;
    }
    out.push_back(m);
  }
  if (scene.cloth)
    for (size_t k = 0; k < scene.cloth->colliders.size(); ++k)
      if (scene.cloth->colliders[k].type == "torus") {
        nlohmann::json m = ring_measures(scene.cloth->colliders[k], t);
        m["collider"] = int(k);
        out.push_back(m);
      }
  return out;
}

nlohmann::json cape_end_state(const Scene& scene, const Trajectory& run, const Trajectory& uncontrolled) {
  if (!scene.character || !scene.cloth || scene.character->target_run.empty()) return nlohmann::json();
  // The end target is the last position and velocity objective pair the character block appended.
  const ObjectiveSpec *pos = nullptr, *vel = nullptr;
  for (const auto& o : scene.objectives) {
    if (o.type == "position" && o.targets.size() > 1) pos = &o;
    if (o.type == "velocity" && o.targets.size() > 1) vel = &o;
  }
  if (!pos || !vel) return nlohmann::json();
  const double length = scene.cloth->height;
  auto rms = [](const VecX& q, const std::vector<Vec3>& t) {
    double sum = 0;
    for (size_t i = 0; i < t.size(); ++i) sum += (seg(q, int(i)) - t[i]).squaredNorm();
    return std::sqrt(sum / double(t.size()));
  };
  auto of = [&](const Trajectory& t) {
    const int f = std::min(pos->frame, t.frames() - 1);
    const double ex = rms(t.x[f], pos->targets);
    return nlohmann::json{{"rms_position_error", ex},
                          {"rms_position_error_percent", 100.0 * ex / length},
                          {"rms_velocity_error", rms(t.v[std::min(vel->frame, t.frames() - 1)], vel->targets)}};
  };
  return {{"frame", pos->frame}, {"cape_length", length}, {"controlled", of(run)}, {"uncontrolled", of(uncontrolled)}};
}

nlohmann::json ring_measures(const ColliderSpec& torus, const Trajectory& t) {
  const TorusCollider ring(torus, 0.0);  // distances only
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
  nlohmann::json m = {{"type", "ring"}};
  m["crossings"] = crossings;
  m["inner_radius"] = inner;
  m["center_of_mass_through_ring"] = crossings > 0 && min_axis < inner;
  m["min_distance_to_ring_axis_when_crossing"] = crossings > 0 ? nlohmann::json(min_axis) : nlohmann::json();
  m["min_signed_distance"] = min_phi;
  m["penetration_free"] = min_phi >= 0;
  return m;
}

}  // namespace kf
