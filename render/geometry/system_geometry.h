#pragma once
// Each particle system's drawing, called by build_frame_geometry (frame_geometry.cpp).
#include "render/geometry/frame_geometry.h"

namespace kf::render {

// Frame f of a flock: agents on the ground plane, shape keyframes, centre-of-mass path, racer circles.
void build_flock(const Scene& scene, const Trajectory& traj, int f, double scale, const GroundPlane& plane,
                 FrameGeometry& g);
// Frame f of a cloth: the two-sided sheet, its colliders and the position and height targets still to come.
void build_cloth(const Scene& scene, const Trajectory& traj, int f, double scale, FrameGeometry& g);
// A collider's surface as triangles (nothing for a ground: see add_ground_square).
void add_collider(Mesh& m, const ColliderShape& shape, const Vec3& color);
// A ground collider as a square around `bounds` (side four times its radius, at least 1 m), facing its normal.
void add_ground_square(Mesh& m, const GroundShape& ground, const Bounds& bounds, const Vec3& color);
// Adds the box a collider shape takes to b (nothing for a ground, which is the floor).
void add_collider_bounds(const ColliderShape& shape, Bounds& b);

}  // namespace kf::render
