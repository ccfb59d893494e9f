#pragma once
// What a chosen range of frames shows, for a camera that frames only those (--view-frames): a character
// with metres of root motion, or a sheet that falls far, is drawn small when the camera frames the whole run.
#include "core/mesh_sequence.h"
#include "core/trajectory.h"
#include "render/camera.h"
#include "scene/scene.h"

namespace kf::render {

// Every particle and body vertex at frames begin..end-1 (end = -1: to the last frame), and the targets of
// the keyframes at those frames. Colliders and the ground are left out: they stand still whatever the
// range. Throws InputError ("--view-frames: ...") when the range is empty or outside the run's frames.
Bounds frame_range_bounds(const Scene& scene, const Trajectory& traj, const MeshSequence* meshes, int begin, int end);

}  // namespace kf::render
