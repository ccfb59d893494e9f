#include "render/geometry/frame_geometry.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include <Eigen/Geometry>

#include "core/check.h"
#include "core/overloaded.h"
#include "render/geometry/height_target.h"
#include "render/geometry/primitives.h"
#include "render/geometry/system_geometry.h"

namespace kf::render {

namespace {

std::atomic<long> g_ground_ids{0};

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
                   [&](const HeightKeyframe& k) {  // its outline around the particles at its frame
                     const VecX& x = traj.x[size_t(std::min(o.frame, traj.frames() - 1))];
                     for (const Vec3& q : height_target_outline(o, k, x, traj.particles, 0.0)) b.add(q);
                   },
               },
               o.kind);
  if (scene.cloth)
    for (const auto& c : scene.cloth->colliders) add_collider_bounds(c.shape, b);
  return b;
}

void build_frame_geometry(const Scene& scene, const Trajectory& traj, int frame, const Bounds& bounds,
                          FrameGeometry& out, const MeshSequence* meshes) {
  CHECK(frame >= 0 && frame < traj.frames());
  CHECK(!meshes || int(meshes->positions.size()) >= traj.frames());
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
}  // namespace kf::render
