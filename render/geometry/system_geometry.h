#pragma once
// Each particle system's drawing, called by build_frame_geometry (frame_geometry.cpp).
#include "render/geometry/frame_geometry.h"

namespace kf::render {

// Frame f of a flock: agents on the ground plane, shape keyframes, centre-of-mass path, racer circles.
void build_flock(const Scene& scene, const Trajectory& traj, int f, double scale, const GroundPlane& plane,
                 FrameGeometry& g);
// Frame f of a cloth: the two-sided sheet, its colliders and the position targets still to come.
void build_cloth(const Scene& scene, const Trajectory& traj, int f, double scale, FrameGeometry& g);
// Adds the box a collider shape takes to b (nothing for a ground, which is the floor).
void add_collider_bounds(const ColliderShape& shape, Bounds& b);

}  // namespace kf::render
