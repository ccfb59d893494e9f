#include "render/geometry/frame_geometry.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include <Eigen/Geometry>

#include "core/overloaded.h"

namespace kf::render {

namespace {

std::atomic<long> g_ground_ids{0};

void set3(float* d, const Vec3& v) {
  d[0] = float(v.x());
  d[1] = float(v.y());
  d[2] = float(v.z());
}

uint32_t add_vertex(Mesh& m, const Vec3& p, const Vec3& n, const Vec3& front, const Vec3& back) {
  Vertex v;
  set3(v.p, p);
  set3(v.n, n);
  set3(v.front, front);
  set3(v.back, back);
  m.vertices.push_back(v);
  return uint32_t(m.vertices.size() - 1);
}

// A flat triangle, front side counter-clockwise.
void add_flat_triangle(Mesh& m, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& color) {
  const Vec3 n = (b - a).cross(c - a).normalized();
  const uint32_t i = add_vertex(m, a, n, color, color);
  add_vertex(m, b, n, color, color);
  add_vertex(m, c, n, color, color);
  m.indices.insert(m.indices.end(), {i, i + 1, i + 2});
}

// Quad a b c d counter-clockwise seen from the front side, flat.
void add_flat_quad(Mesh& m, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const Vec3& n,
                   const Vec3& color) {
  const uint32_t i = add_vertex(m, a, n, color, color);
  add_vertex(m, b, n, color, color);
  add_vertex(m, c, n, color, color);
  add_vertex(m, d, n, color, color);
  m.indices.insert(m.indices.end(), {i, i + 1, i + 2, i, i + 2, i + 3});
}

Vec3 any_perpendicular(const Vec3& n) {
  const Vec3 a = std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitZ();
  return n.cross(a).normalized();
}

// A strip of `width` metres along `points` lying in the plane with normal `n`.
void add_ribbon(Mesh& m, const std::vector<Vec3>& points, bool closed, double width, const Vec3& n,
                const Vec3& color) {
  const size_t count = points.size();
  if (count < 2) return;
  const size_t segments = closed ? count : count - 1;
  for (size_t s = 0; s < segments; ++s) {
    const Vec3 a = points[s], b = points[(s + 1) % count];
    const Vec3 d = b - a;
    if (d.norm() < 1e-12) continue;
    const Vec3 t = d.normalized();
    const Vec3 side = n.cross(t) * (0.5 * width);
    // Extending each segment by half a width closes the gaps at the corners.
    const Vec3 a2 = a - t * (0.5 * width), b2 = b + t * (0.5 * width);
    add_flat_quad(m, a2 - side, b2 - side, b2 + side, a2 + side, n, color);
  }
}

std::vector<Vec3> circle_points(const Vec3& c, const Vec3& n, double radius, int segments) {
  const Vec3 u = any_perpendicular(n), w = n.cross(u);
  std::vector<Vec3> pts;
  for (int k = 0; k < segments; ++k) {
    const double a = 2.0 * M_PI * k / segments;
    pts.push_back(c + radius * (std::cos(a) * u + std::sin(a) * w));
  }
  return pts;
}

void add_disc(Mesh& m, const Vec3& c, const Vec3& n, double radius, const Vec3& color) {
  const auto pts = circle_points(c, n, radius, 24);
  const uint32_t center = add_vertex(m, c, n, color, color);
  for (size_t k = 0; k < pts.size(); ++k) add_vertex(m, pts[k], n, color, color);
  for (uint32_t k = 0; k < pts.size(); ++k)
    m.indices.insert(m.indices.end(), {center, center + 1 + k, center + 1 + (k + 1) % uint32_t(pts.size())});
}

// A smooth surface from a (u, v) parameterisation with `nu` x `nv` quads, both directions periodic.
template <class Surface>
void add_periodic_surface(Mesh& m, int nu, int nv, const Vec3& color, Surface surface) {
  const uint32_t base = uint32_t(m.vertices.size());
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) {
      Vec3 p, n;
      surface(2.0 * M_PI * i / nu, 2.0 * M_PI * j / nv, p, n);
      add_vertex(m, p, n, color, color);
    }
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const uint32_t a = base + j * (nu + 1) + i, b = a + 1, c = a + (nu + 1) + 1, d = a + (nu + 1);
      m.indices.insert(m.indices.end(), {a, b, c, a, c, d});
    }
}

void add_sphere(Mesh& m, const Vec3& center, double r, const Vec3& color) {
  add_periodic_surface(m, 48, 24, color, [&](double u, double v, Vec3& p, Vec3& n) {
    const double theta = 0.5 * v;  // 0..pi
    n = Vec3(std::sin(theta) * std::cos(u), std::cos(theta), -std::sin(theta) * std::sin(u));
    p = center + r * n;
  });
}

void add_torus(Mesh& m, const Vec3& center, const Vec3& axis, double R, double r, const Vec3& color) {
  const Vec3 a = axis.normalized(), e1 = any_perpendicular(a), e2 = a.cross(e1);
  add_periodic_surface(m, 64, 20, color, [&](double u, double v, Vec3& p, Vec3& n) {
    const Vec3 radial = std::cos(u) * e1 + std::sin(u) * e2;
    n = std::cos(v) * radial + std::sin(v) * a;
    p = center + R * radial + r * n;
  });
}

// A capsule: the hemisphere at b (rows 0..kRows), the cylinder (one band), the hemisphere at a.
void add_capsule(Mesh& m, const Vec3& a, const Vec3& b, double r, const Vec3& color) {
  const Vec3 e = (b - a).normalized(), e1 = any_perpendicular(e), e2 = e.cross(e1);
  constexpr int kRows = 12;  // per cap
  add_periodic_surface(m, 48, 2 * kRows + 1, color, [&](double u, double v, Vec3& p, Vec3& n) {
    const int j = int(std::lround(v * (2 * kRows + 1) / (2.0 * M_PI)));
    const bool at_b = j <= kRows;
    const double theta = 0.5 * M_PI * (at_b ? j : j - 1) / kRows;  // from b's pole (0) to a's (pi)
    n = std::cos(theta) * e + std::sin(theta) * (std::cos(u) * e1 + std::sin(u) * e2);
    p = (at_b ? b : a) + r * n;
  });
}

// Small octahedron: a target point in space.
void add_marker(Mesh& m, const Vec3& c, double s, const Vec3& color) {
  const Vec3 X = Vec3::UnitX() * s, Y = Vec3::UnitY() * s, Z = Vec3::UnitZ() * s;
  const Vec3 dirs[4] = {X, Z, -X, -Z};
  for (int k = 0; k < 4; ++k) {
    add_flat_triangle(m, c + Y, c + dirs[k], c + dirs[(k + 1) % 4], color);
    add_flat_triangle(m, c - Y, c + dirs[(k + 1) % 4], c + dirs[k], color);
  }
}

Vec3 mix(const Vec3& a, const Vec3& b, double t) { return (1 - t) * a + t * b; }

// Each collider shape's drawing and the box it takes (a ground is drawn as the floor, ground_plane()).
void add_collider(Mesh& m, const ColliderShape& shape, const Vec3& color) {
  std::visit(Overloaded{
                 [](const GroundShape&) {},
                 [&](const SphereShape& s) { add_sphere(m, s.center, s.radius, color); },
                 [&](const TorusShape& t) { add_torus(m, t.center, t.axis, t.radius, t.tube_radius, color); },
                 [&](const CapsuleShape& c) { add_capsule(m, c.a, c.b, c.radius, color); },
             },
             shape);
}

void add_collider_bounds(const ColliderShape& shape, Bounds& b) {
  std::visit(Overloaded{
                 [](const GroundShape&) {},
                 [&](const SphereShape& s) {
                   b.add(s.center - Vec3::Constant(s.radius));
                   b.add(s.center + Vec3::Constant(s.radius));
                 },
                 [&](const TorusShape& t) {
                   b.add(t.center - Vec3::Constant(t.radius + t.tube_radius));
                   b.add(t.center + Vec3::Constant(t.radius + t.tube_radius));
                 },
                 [&](const CapsuleShape& c) {
                   b.add(c.a.cwiseMin(c.b) - Vec3::Constant(c.radius));
                   b.add(c.a.cwiseMax(c.b) + Vec3::Constant(c.radius));
                 },
             },
             shape);
}

GroundPlane ground_plane(const Scene& scene, const Bounds& bounds) {
  GroundPlane g;
  visit_system(scene, Overloaded{
                          [](const FlockSpec&) {},  // flocks live on y = 0
                          [&](const ClothSpec& cloth) {
                            for (const auto& c : cloth.colliders)
                              if (const auto* ground = std::get_if<GroundShape>(&c.shape)) {
                                g.normal = ground->normal.normalized();
                                g.offset = g.normal.dot(ground->point);
                                return;
                              }
                            // No floor in the scene: put one just below everything so the shadows show the
                            // height.
                            g.offset = bounds.empty() ? 0.0
                                                      : std::min(0.0, bounds.lo.y() - 0.05 * std::max(bounds.radius(), 0.25));
                          },
                      });
  return g;
}

double scene_scale(const Bounds& b) { return std::max(b.empty() ? 1.0 : b.radius(), 0.25); }

// A big square of alternating tiles so motion and distance read.
void build_ground(const Scene& scene, const Bounds& bounds, const GroundPlane& plane, double scale, Mesh& m) {
  m.clear();
  const RenderSpec& rs = scene.render;
  if (!rs.ground) return;
  const Vec3 n = plane.normal;
  const Vec3 u = std::abs(n.y()) > 0.9 ? Vec3::UnitX() : any_perpendicular(n);
  const Vec3 w = n.cross(u);
  const Vec3 c0 = bounds.empty() ? Vec3::Zero() : bounds.center();
  const Vec3 origin = c0 - n * (n.dot(c0) - plane.offset);
  const double tile = 0.25 * std::pow(10.0, std::floor(std::log10(scale) + 0.5));
  const int half_tiles = std::min(60, int(std::ceil(8.0 * scale / tile)));
  // Tiles are aligned to world multiples of `tile` so they stay put between runs of different length.
  const double su = std::floor(origin.dot(u) / tile), sw = std::floor(origin.dot(w) / tile);
  const Vec3 base = origin - u * (origin.dot(u) - su * tile) - w * (origin.dot(w) - sw * tile);
  const Vec3 dark = rs.ground_color * 0.93;
  for (int b = -half_tiles; b < half_tiles; ++b)
    for (int a = -half_tiles; a < half_tiles; ++a) {
      const Vec3 p = base + u * (a * tile) + w * (b * tile);
      const bool odd = ((a + b + long(su) + long(sw)) & 1) != 0;
      add_flat_quad(m, p, p + u * tile, p + (u + w) * tile, p + w * tile, n, odd ? dark : rs.ground_color);
    }
}

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

void build_flock(const Scene& scene, const Trajectory& traj, int f, double scale, const GroundPlane& plane,
                 FrameGeometry& g) {
  const RenderSpec& rs = scene.render;
  const int p = traj.particles;
  const double len = rs.agent_size, line = 0.12 * len, lift = 0.002 * scale;
  const Vec3 n = Vec3::UnitY();
  auto on_ground = [&](double x, double z) { return Vec3(x, plane.offset + lift, z); };
  std::vector<char> highlighted(p, 0);
  // The next shape keyframe is drawn strongly, the others faded.
  int next_shape = -1;
  for (size_t k = 0; k < scene.objectives.size(); ++k) {
    const auto& o = scene.objectives[k];
    if (std::holds_alternative<ShapeKeyframe>(o.kind) && o.frame >= f &&
        (next_shape < 0 || o.frame < scene.objectives[next_shape].frame))
      next_shape = int(k);
  }
  std::vector<std::pair<int, Vec3>> com;  // (frame, target) of the centre-of-mass keyframes
  for (size_t k = 0; k < scene.objectives.size(); ++k) {
    const auto& o = scene.objectives[k];
    std::visit(Overloaded{
                   [&](const ShapeKeyframe& shape) {
                     std::vector<Vec3> pts;
                     for (const Vec2& q : shape.polygon) pts.push_back(on_ground(q.x(), q.y()));
                     const Vec3 color =
                         int(k) == next_shape ? rs.target_color : mix(rs.target_color, rs.ground_color, 0.6);
                     add_ribbon(g.marks, pts, true, line, n, color);
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
    add_ribbon(g.marks, pts, false, line, n, rs.path_color);
    for (size_t k = 1; k < pts.size(); ++k) add_disc(g.marks, pts[k], n, 2.0 * line, rs.path_color);
  }
  for (int i = 0; i < p; ++i) {
    const Vec3 x = seg(traj.x[f], i);
    const Vec3 pos(x.x(), plane.offset + lift, x.z());
    add_agent(g.objects, pos, heading_of(traj, f, i), len, highlighted[i] ? rs.highlight_color : rs.agent_color);
    if (highlighted[i])
      add_ribbon(g.marks, circle_points(pos, n, 0.9 * len, 40), true, line, n, rs.highlight_color);
  }
}

void build_cloth(const Scene& scene, const Trajectory& traj, int f, double scale, FrameGeometry& g) {
  const RenderSpec& rs = scene.render;
  const int nx = scene.cloth->nx, ny = scene.cloth->ny;
  const VecX& x = traj.x[f];
  auto P = [&](int i, int j) -> Vec3 { return seg(x, j * nx + i); };
  // Smooth normals from central differences of the grid.
  std::vector<Vec3> normal(size_t(nx) * ny);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const Vec3 du = P(std::min(i + 1, nx - 1), j) - P(std::max(i - 1, 0), j);
      const Vec3 dv = P(i, std::min(j + 1, ny - 1)) - P(i, std::max(j - 1, 0));
      const Vec3 c = du.cross(dv);
      normal[size_t(j) * nx + i] = c.norm() > 1e-15 ? c.normalized() : Vec3::UnitY();
    }
  const int squares = rs.checker;
  Mesh& m = g.objects;
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      bool odd = false;
      if (squares > 0) {
        const int si = (i * squares) / (nx - 1), sj = (j * squares) / (ny - 1);
        odd = ((si + sj) & 1) != 0;
      }
      const Vec3 front = odd ? rs.cloth_front * 0.72 : rs.cloth_front;
      const Vec3 back = odd ? rs.cloth_back * 0.8 : rs.cloth_back;
      const uint32_t base = uint32_t(m.vertices.size());
      const int ci[4] = {i, i + 1, i + 1, i}, cj[4] = {j, j, j + 1, j + 1};
      for (int k = 0; k < 4; ++k)
        add_vertex(m, P(ci[k], cj[k]), normal[size_t(cj[k]) * nx + ci[k]], front, back);
      m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    }
  for (const auto& c : scene.cloth->colliders) add_collider(m, c.shape, rs.collider_color);
  // Targets of the keyframes still to come, small beside their own spacing so a sheet of targets does
  // not hide the cloth that reaches it. A blend's end target (a whole other take's cape) is drawn at its
  // own frame only: over the cape in every frame it would hide the blend.
  size_t markers = 0;
  for (const auto& o : scene.objectives) {
    const auto* position = std::get_if<PositionKeyframe>(&o.kind);
    if (!position || o.frame < f || position->targets.empty()) continue;
    if (o.source == ObjectiveSource::kEndTarget && o.frame != f) continue;
    const std::vector<Vec3>& targets = position->targets;
    Bounds tb;
    for (const Vec3& q : targets) tb.add(q);
    const double spacing = 2 * tb.radius() / std::sqrt(double(targets.size()));
    const double size = targets.size() > 1 ? std::min(0.012 * scale, 0.2 * spacing) : 0.012 * scale;
    for (const Vec3& q : targets)
      if (markers++ < 4096) add_marker(m, q, size, rs.target_color);
  }
}

}  // namespace

void add_body_mesh(const MeshSequence& seq, int frame, int mesh, const Vec3& color, Mesh& out) {
  const SequenceMesh& sm = seq.meshes[size_t(mesh)];
  const float* p = seq.vertex_positions(frame, mesh);
  auto P = [&](uint32_t i) { return Vec3(p[3 * i], p[3 * i + 1], p[3 * i + 2]); };
  std::vector<Vec3> normal(size_t(sm.vertices), Vec3::Zero());
  for (size_t t = 0; t + 2 < sm.triangles.size(); t += 3) {
    const uint32_t a = sm.triangles[t], b = sm.triangles[t + 1], c = sm.triangles[t + 2];
    const Vec3 n = (P(b) - P(a)).cross(P(c) - P(a));  // length = twice the area: the weight
    normal[a] += n;
    normal[b] += n;
    normal[c] += n;
  }
  const uint32_t base = uint32_t(out.vertices.size());
  for (int i = 0; i < sm.vertices; ++i) {
    const Vec3& n = normal[size_t(i)];
    add_vertex(out, P(uint32_t(i)), n.norm() > 1e-30 ? n.normalized() : Vec3::UnitY(), color, color);
  }
  for (uint32_t i : sm.triangles) out.indices.push_back(base + i);
}

Bounds scene_bounds(const Scene& scene, const Trajectory& traj, const MeshSequence* meshes) {
  Bounds b;
  if (meshes)
    for (const auto& f : meshes->positions)
      for (size_t i = 0; i + 2 < f.size(); i += 3) b.add(Vec3(f[i], f[i + 1], f[i + 2]));
  for (const VecX& x : traj.x)
    for (int i = 0; i < traj.particles; ++i) b.add(seg(x, i));
  for (const auto& o : scene.objectives)
    std::visit(Overloaded{
                   [&](const PositionKeyframe& k) { for (const Vec3& q : k.targets) b.add(q); },
                   [&](const VelocityKeyframe& k) { for (const Vec3& q : k.targets) b.add(q); },
                   [&](const CenterOfMassKeyframe& k) { b.add(k.target); },
                   [&](const ShapeKeyframe& k) { for (const Vec2& q : k.polygon) b.add(Vec3(q.x(), 0.0, q.y())); },
                   [](const ArchKeyframe&) {},
               },
               o.kind);
  if (scene.cloth)
    for (const auto& c : scene.cloth->colliders) add_collider_bounds(c.shape, b);
  return b;
}

void build_frame_geometry(const Scene& scene, const Trajectory& traj, int frame, const Bounds& bounds,
                          FrameGeometry& out, const MeshSequence* meshes) {
  out.scale = scene_scale(bounds);
  const GroundPlane plane = ground_plane(scene, bounds);
  if (out.ground.vertices.empty() || plane.normal != out.plane.normal || plane.offset != out.plane.offset) {
    out.plane = plane;
    build_ground(scene, bounds, plane, out.scale, out.ground);
    out.ground_id = ++g_ground_ids;
  }
  out.marks.clear();
  out.objects.clear();
  visit_system(scene, Overloaded{
                          [&](const FlockSpec&) { build_flock(scene, traj, frame, out.scale, out.plane, out); },
                          [&](const ClothSpec&) { build_cloth(scene, traj, frame, out.scale, out); },
                      });
  if (meshes)
    for (int k = 0; k < int(meshes->meshes.size()); ++k) add_body_mesh(*meshes, frame, k, scene.render.body_color, out.objects);
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
