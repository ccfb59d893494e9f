#include <algorithm>

#include "core/overloaded.h"
#include "render/geometry/primitives.h"
#include "render/geometry/system_geometry.h"

namespace kf::render {

namespace {

Vec3 heading_of(const Trajectory& traj, int f, int i) {
  Vec2 h(traj.v[f][3 * i], traj.v[f][3 * i + 2]);
  if (h.norm() < 1e-9) {
    const int g = f + 1 < traj.frames() ? f + 1 : f, e = f + 1 < traj.frames() ? f : std::max(f - 1, 0);
    h = Vec2(traj.x[g][3 * i] - traj.x[e][3 * i], traj.x[g][3 * i + 2] - traj.x[e][3 * i + 2]);
  }
  if (h.norm() < 1e-12) return Vec3::UnitX();
  h.normalize();
  return Vec3(h.x(), 0.0, h.y());
}

// A low dart pointing along the heading; its ridge catches the light so the direction reads from above.
void add_agent(Mesh& m, const Vec3& pos, const Vec3& heading, double len, const Vec3& color) {
  const Vec3 up = Vec3::UnitY(), side = heading.cross(up).normalized();
  const Vec3 base(pos.x(), pos.y(), pos.z());
  const Vec3 tip = base + heading * (0.55 * len), notch = base - heading * (0.2 * len);
  const Vec3 left = base - heading * (0.45 * len) - side * (0.38 * len);
  const Vec3 right = base - heading * (0.45 * len) + side * (0.38 * len);
  const Vec3 top = base + up * (0.22 * len);
  add_flat_triangle(m, top, left, tip, color);
  add_flat_triangle(m, top, tip, right, color);
  add_flat_triangle(m, top, notch, left, color);
  add_flat_triangle(m, top, right, notch, color);
}

// The first shape keyframe at or after frame f (-1: none).
int next_shape_keyframe(const Scene& scene, int f) {
  int next = -1;
  for (size_t k = 0; k < scene.objectives.size(); ++k) {
    const auto& o = scene.objectives[k];
    if (std::holds_alternative<ShapeKeyframe>(o.kind) && o.frame >= f &&
        (next < 0 || o.frame < scene.objectives[next].frame))
      next = int(k);
  }
  return next;
}

// A centre-of-mass path on the ground: a line through its points and a dot at each target.
void add_path(Mesh& m, const std::vector<Vec3>& pts, double line, const Vec3& color) {
  const Vec3 n = Vec3::UnitY();
  add_ribbon(m, pts, false, line, n, color);
  for (size_t k = 1; k < pts.size(); ++k) add_disc(m, pts[k], n, 2.0 * line, color);
}

// Every agent of frame f at height y, a highlighted agent ringed.
void add_agents(const RenderSpec& rs, const Trajectory& traj, int f, double y, const std::vector<char>& highlighted,
                FrameGeometry& g) {
  const double len = rs.agent_size, line = 0.12 * len;
  for (int i = 0; i < traj.particles; ++i) {
    const Vec3 x = seg(traj.x[f], i);
    const Vec3 pos(x.x(), y, x.z());
    add_agent(g.objects, pos, heading_of(traj, f, i), len, highlighted[i] ? rs.highlight_color : rs.agent_color);
    if (highlighted[i])
      add_ribbon(g.marks, circle_points(pos, Vec3::UnitY(), 0.9 * len, 40), true, line, Vec3::UnitY(),
                 rs.highlight_color);
  }
}

}  // namespace

void build_flock(const Scene& scene, const Trajectory& traj, int f, double scale, const GroundPlane& plane,
                 FrameGeometry& g) {
  const RenderSpec& rs = scene.render;
  const int p = traj.particles;
  const double len = rs.agent_size, line = 0.12 * len, lift = 0.002 * scale;
  const Vec3 n = Vec3::UnitY();
  auto on_ground = [&](double x, double z) { return Vec3(x, plane.offset + lift, z); };
  std::vector<char> highlighted(p, 0);
  const int next_shape = next_shape_keyframe(scene, f);  // drawn strongly, the others faded
  std::vector<std::pair<int, Vec3>> com;  // (frame, target) of the centre-of-mass keyframes
  for (size_t k = 0; k < scene.objectives.size(); ++k) {
    const auto& o = scene.objectives[k];
    std::visit(Overloaded{
                   [&](const ShapeKeyframe& shape) {
                     const Vec3 color =
                         int(k) == next_shape ? rs.target_color : mix(rs.target_color, rs.ground_color, 0.6);
                     auto outline = [&](const std::vector<Vec2>& loop) {
                       std::vector<Vec3> pts;
                       for (const Vec2& q : loop) pts.push_back(on_ground(q.x(), q.y()));
                       add_ribbon(g.marks, pts, true, line, n, color);
                     };
                     outline(shape.polygon);
                     for (const auto& hole : shape.holes) outline(hole);
                   },
                   [&](const CenterOfMassKeyframe& c) { com.emplace_back(o.frame, c.target); },
                   [&](const PositionKeyframe& pk) {
                     const bool single = o.particles.size() == 1;
                     for (const Vec3& q : pk.targets) {
                       if (single) {
                         add_ribbon(g.marks, circle_points(on_ground(q.x(), q.z()), n, 0.6 * len, 32), true,
                                    0.6 * line, n, rs.target_color);
                       } else {
                         add_disc(g.marks, on_ground(q.x(), q.z()), n, 0.15 * len, rs.target_color);
                       }
                     }
                     if (single) highlighted[o.particles[0]] = 1;
                   },
                   [](const VelocityKeyframe&) {},  // not drawn
                   [](const ArchKeyframe&) {},      // cloth only
                   [](const HeightKeyframe&) {},    // cloth only
               },
               o.kind);
  }
  if (!com.empty()) {
    std::stable_sort(com.begin(), com.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    Vec3 c0 = Vec3::Zero();
    for (int i = 0; i < p; ++i) c0 += seg(traj.x[0], i);
    c0 /= std::max(p, 1);
    std::vector<Vec3> pts = {on_ground(c0.x(), c0.z())};
    for (const auto& [frame, target] : com) pts.push_back(on_ground(target.x(), target.z()));
    add_path(g.marks, pts, line, rs.path_color);
  }
  add_agents(rs, traj, f, plane.offset + lift, highlighted, g);
}

void add_flock_path(const Scene& scene, const Trajectory& traj, const std::vector<int>& snapshots,
                    FrameGeometry& g) {
  const RenderSpec& rs = scene.render;
  const int p = traj.particles, frames = traj.frames();
  const double len = rs.agent_size, line = 0.12 * len, lift = 0.003 * g.scale;
  const Vec3 n = Vec3::UnitY();
  auto on_ground = [&](const Vec3& x) { return Vec3(x.x(), g.plane.offset + lift, x.z()); };
  // Earlier snapshots: the agents again, paler the older they are (the last one is drawn already).
  for (size_t k = 0; k + 1 < snapshots.size(); ++k) {
    const double fade = 0.7 - 0.45 * double(k) / double(std::max<size_t>(snapshots.size() - 1, 1));
    for (int i = 0; i < p; ++i)
      add_agent(g.objects, on_ground(seg(traj.x[snapshots[k]], i)), heading_of(traj, snapshots[k], i), len,
                mix(rs.agent_color, rs.ground_color, fade));
  }
  // Trails of a few agents spread across the flock, fading from pale (start) to the agent colour.
  std::vector<int> order(static_cast<size_t>(p));
  for (int i = 0; i < p; ++i) order[size_t(i)] = i;
  std::sort(order.begin(), order.end(), [&](int a, int b) { return traj.x[0][3 * a] < traj.x[0][3 * b]; });
  const int trails = std::min(p, 6);
  for (int t = 0; t < trails; ++t) {
    const int i = order[size_t(t * (p - 1) / std::max(trails - 1, 1))];
    for (int f = 0; f + 1 < frames; ++f) {
      const double age = 1.0 - double(f) / double(std::max(frames - 2, 1));
      add_ribbon(g.marks, {on_ground(seg(traj.x[f], i)), on_ground(seg(traj.x[f + 1], i))}, false, line, n,
                 mix(rs.highlight_color, rs.ground_color, 0.7 * age));
    }
  }
  // The flock's centre of mass, frame by frame: the path it actually took, over the keyframed one.
  std::vector<Vec3> centre;
  for (int f = 0; f < frames; ++f) {
    Vec3 c = Vec3::Zero();
    for (int i = 0; i < p; ++i) c += seg(traj.x[f], i);
    centre.push_back(on_ground(c / std::max(p, 1)) + n * lift);
  }
  add_ribbon(g.marks, centre, false, 1.5 * line, n, mix(rs.agent_color, Vec3::Zero(), 0.3));
}


}  // namespace kf::render
