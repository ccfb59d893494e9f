#pragma once
// Everything one frame shows, as triangles both back ends draw the same way.
//
// Three meshes: the ground (receives shadows), marks lying just above the ground (keyframe polygons,
// paths, circles: receive shadows, cast none), and objects (agents, cloth, colliders, target markers:
// cast shadows). Each vertex has a front and a back colour, so the cloth is two-sided.
#include <cstdint>
#include <vector>

#include "core/mesh_sequence.h"
#include "core/trajectory.h"
#include "render/camera.h"
#include "scene/scene.h"

namespace kf::render {

struct Vertex {
  float p[3];      // position, metres, world frame
  float n[3];      // unit normal of the front side
  float front[3];  // RGB in [0, 1]
  float back[3];
};

struct Mesh {
  std::vector<Vertex> vertices;
  std::vector<uint32_t> indices;  // 3 per triangle, counter-clockwise seen from the front
  int triangles() const { return int(indices.size() / 3); }
  void clear() { vertices.clear(); indices.clear(); }
};

// A plane the shadows fall on: points x with normal·x = offset.
struct GroundPlane {
  Vec3 normal = Vec3::UnitY();
  double offset = 0.0;
};

struct FrameGeometry {
  Mesh ground, marks, objects;
  GroundPlane plane;
  double scale = 1.0;  // metres; the scene's size, for offsets that must not depend on units
  long ground_id = 0;  // changes whenever `ground` was rebuilt (back ends keep it otherwise)
};

// Bounding box of the trajectory (and `meshes`, if any) over all frames plus the keyframe targets it
// should show.
Bounds scene_bounds(const Scene& scene, const Trajectory& traj, const MeshSequence* meshes = nullptr);

// Appends mesh `mesh` of `seq` at `frame` to `out`: one colour both sides, area-weighted vertex normals.
void add_body_mesh(const MeshSequence& seq, int frame, int mesh, const Vec3& color, Mesh& out);

// Builds frame `frame` (0 <= frame < traj.frames()) of `scene` into `out`, reusing its storage.
// `meshes` (frame count as traj, may be null): drawn among the objects in the body colour, smooth shaded.
void build_frame_geometry(const Scene& scene, const Trajectory& traj, int frame, const Bounds& bounds,
                          FrameGeometry& out, const MeshSequence* meshes = nullptr);

// A flock's path in one picture (paper fig. 3), added to a frame built by build_frame_geometry for the
// last of `snapshots`: the agents at the earlier snapshots, paler the older; the trails of six agents
// spread across the flock, fading towards the start; the centre of mass frame by frame as a dark line
// beside the keyframed path (drawn by the frame already, with its keyframe markers).
void add_flock_path(const Scene& scene, const Trajectory& traj, const std::vector<int>& snapshots,
                    FrameGeometry& g);

}  // namespace kf::render
