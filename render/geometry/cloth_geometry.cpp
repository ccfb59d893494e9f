#include <algorithm>
#include <cmath>

#include "core/check.h"
#include "core/box_frame.h"
#include "core/overloaded.h"
#include "render/geometry/height_target.h"
#include "render/geometry/primitives.h"
#include "render/geometry/system_geometry.h"

namespace kf::render {

namespace {
void add_box_corners(const Vec3& c, const Mat3& axes, const Vec3& half, Bounds& b) {
  for (int k = 0; k < 8; ++k)
    b.add(c + axes * Vec3(k & 1 ? half.x() : -half.x(), k & 2 ? half.y() : -half.y(), k & 4 ? half.z() : -half.z()));
}
}  // namespace

void add_collider(Mesh& m, const ColliderShape& shape, const Vec3& color) {
  std::visit(Overloaded{
                 [](const GroundShape&) {},
                 [&](const SphereShape& s) { add_sphere(m, s.center, s.radius, color); },
                 [&](const TorusShape& t) { add_torus(m, t.center, t.axis, t.radius, t.tube_radius, color); },
                 [&](const CapsuleShape& c) { add_capsule(m, c.a, c.b, c.radius, color); },
                 [&](const BoxShape& s) {
                   add_rounded_box(m, s.center, box_frame(s.u_axis, s.v_axis), 0.5 * s.size - Vec3::Constant(s.radius),
                                   s.radius, color);
                 },
                 [&](const RectangleShape& s) {  // both sides, each facing out
                   const Mat3 r = box_frame(s.u_axis, s.v_axis);
                   const Vec3 u = 0.5 * s.width * r.col(0), v = 0.5 * s.height * r.col(1), c = s.center;
                   add_flat_quad(m, c - u - v, c + u - v, c + u + v, c - u + v, r.col(2), color);
                   add_flat_quad(m, c - u - v, c - u + v, c + u + v, c + u - v, -r.col(2), color);
                 },
             },
             shape);
}

void add_ground_square(Mesh& m, const GroundShape& ground, const Bounds& bounds, const Vec3& color) {
  const Vec3 n = ground.normal.normalized();
  const Vec3 c0 = bounds.empty() ? ground.point : bounds.center();
  const Vec3 c = c0 - n * n.dot(c0 - ground.point);  // the box's centre dropped onto the plane
  const double half = 2.0 * std::max(bounds.empty() ? 1.0 : bounds.radius(), 0.25);
  const Vec3 u = any_perpendicular(n) * half, v = n.cross(u);
  add_flat_quad(m, c - u - v, c + u - v, c + u + v, c - u + v, n, color);
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
                 [&](const BoxShape& s) { add_box_corners(s.center, box_frame(s.u_axis, s.v_axis), 0.5 * s.size, b); },
                 [&](const RectangleShape& s) {
                   add_box_corners(s.center, box_frame(s.u_axis, s.v_axis), Vec3(0.5 * s.width, 0.5 * s.height, 0), b);
                 },
             },
             shape);
}

namespace {
// A mesh cloth's triangles with area-weighted vertex normals, in a checker of rest-space squares (the two
// widest axes of its rest box).
void add_mesh_cloth(const ClothMesh& mesh, const VecX& x, const RenderSpec& rs, Mesh& m) {
  const std::vector<int> tri = mesh.triangles();
  std::vector<Vec3> normal(mesh.vertices.size(), Vec3::Zero());
  for (size_t t = 0; t < tri.size(); t += 3) {
    const Vec3 a = seg(x, tri[t]), n = (Vec3(seg(x, tri[t + 1])) - a).cross(Vec3(seg(x, tri[t + 2])) - a);
    for (int k = 0; k < 3; ++k) normal[size_t(tri[t + k])] += n;
  }
  for (Vec3& n : normal) n = n.norm() > 1e-15 ? Vec3(n.normalized()) : Vec3::UnitY();
  Bounds rest;
  for (const Vec3& p : mesh.vertices) rest.add(p);
  const Vec3 lo = rest.empty() ? Vec3::Zero() : rest.lo, size = rest.empty() ? Vec3::Ones() : Vec3(rest.hi - rest.lo);
  int axes[3] = {0, 1, 2};
  std::sort(axes, axes + 3, [&](int a, int b) { return size[a] > size[b]; });
  const double side = std::max(size[axes[0]], 1e-9);
  for (size_t t = 0; t < tri.size(); t += 3) {
    bool odd = false;
    if (rs.checker > 0) {
      const Vec3 c = (mesh.vertices[size_t(tri[t])] + mesh.vertices[size_t(tri[t + 1])] + mesh.vertices[size_t(tri[t + 2])]) / 3;
      const int si = int(std::floor((c[axes[0]] - lo[axes[0]]) / side * rs.checker));
      const int sj = int(std::floor((c[axes[1]] - lo[axes[1]]) / side * rs.checker));
      odd = ((si + sj) & 1) != 0;
    }
    const Vec3 front = odd ? rs.cloth_front * 0.72 : rs.cloth_front;
    const Vec3 back = odd ? rs.cloth_back * 0.8 : rs.cloth_back;
    const uint32_t base = uint32_t(m.vertices.size());
    for (int k = 0; k < 3; ++k) add_vertex(m, seg(x, tri[t + k]), normal[size_t(tri[t + k])], front, back);
    m.indices.insert(m.indices.end(), {base, base + 1, base + 2});
  }
}

// The grid's quads with smooth normals from central differences, in a checker of `squares` per side.
void add_grid_cloth(const ClothSpec& cloth, const VecX& x, const RenderSpec& rs, Mesh& m) {
  const int nx = cloth.nx, ny = cloth.ny;
  auto P = [&](int i, int j) -> Vec3 { return seg(x, j * nx + i); };
  std::vector<Vec3> normal(size_t(nx) * ny);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const Vec3 du = P(std::min(i + 1, nx - 1), j) - P(std::max(i - 1, 0), j);
      const Vec3 dv = P(i, std::min(j + 1, ny - 1)) - P(i, std::max(j - 1, 0));
      const Vec3 c = du.cross(dv);
      normal[size_t(j) * nx + i] = c.norm() > 1e-15 ? c.normalized() : Vec3::UnitY();
    }
  const int squares = rs.checker;
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
}
}  // namespace

void build_cloth(const Scene& scene, const Trajectory& traj, int f, double scale, FrameGeometry& g) {
  const RenderSpec& rs = scene.render;
  // Run directories are validated against their scene when read.
  CHECK_EQ(traj.particles, scene.cloth->particles());
  Mesh& m = g.objects;
  if (scene.cloth->mesh) add_mesh_cloth(*scene.cloth->mesh, traj.x[f], rs, m);
  else add_grid_cloth(*scene.cloth, traj.x[f], rs, m);
  for (const auto& c : scene.cloth->colliders) add_collider(m, c.shape, rs.collider_color);
  // Targets of the keyframes still to come, small beside their own spacing so a sheet of targets does
  // not hide the cloth that reaches it. A blend's end target (a whole other take's cape) is drawn at its
  // own frame only: over the cape in every frame it would hide the blend. A height's target is a thin
  // level outline around its particles.
  size_t markers = 0;
  for (const auto& o : scene.objectives) {
    if (const auto* height = std::get_if<HeightKeyframe>(&o.kind); height && o.frame >= f) {
      const std::vector<Vec3> outline = height_target_outline(o, *height, traj.x[f], traj.particles, 0.05 * scale);
      if (!outline.empty()) add_ribbon(m, outline, true, 0.006 * scale, Vec3::UnitY(), rs.target_color);
      continue;
    }
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

}  // namespace kf::render
