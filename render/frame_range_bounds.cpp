#include "render/frame_range_bounds.h"

#include <string>

#include "core/error.h"
#include "core/overloaded.h"
#include "render/geometry/height_target.h"

namespace kf::render {

Bounds frame_range_bounds(const Scene& scene, const Trajectory& traj, const MeshSequence* meshes, int begin, int end) {
  const int frames = traj.frames();
  if (end < 0) end = frames;
  if (begin >= end || end > frames)
    throw InputError("--view-frames: expected frames within 0:" + std::to_string(frames) + " (the run's frames 0.." +
                     std::to_string(frames - 1) + "), got " + std::to_string(begin) + ":" + std::to_string(end));
  Bounds b;
  for (int f = begin; f < end; ++f) {
    for (int i = 0; i < traj.particles; ++i) b.add(traj.x[size_t(f)].segment<3>(3 * i));
    if (!meshes) continue;
    const auto& p = meshes->positions[size_t(f)];
    for (size_t i = 0; i + 2 < p.size(); i += 3) b.add(Vec3(p[i], p[i + 1], p[i + 2]));
  }
  for (const ObjectiveSpec& o : scene.objectives) {
    if (o.frame < begin || o.frame >= end) continue;
    std::visit(Overloaded{
                   [&](const PositionKeyframe& k) { for (const Vec3& q : k.targets) b.add(q); },
                   [&](const CenterOfMassKeyframe& k) { b.add(k.target); },
                   [&](const ShapeKeyframe& k) { for (const Vec2& q : k.polygon) b.add(Vec3(q.x(), 0.0, q.y())); },
                   [](const VelocityKeyframe&) {},  // a velocity is no place
                   [](const ArchKeyframe&) {},
                   [&](const HeightKeyframe& k) {  // its outline around the particles at its frame
                     for (const Vec3& q : height_target_outline(o, k, traj.x[size_t(o.frame)], traj.particles, 0.0))
                       b.add(q);
                   },
               },
               o.kind);
  }
  return b;
}

}  // namespace kf::render
