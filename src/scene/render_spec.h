#pragma once
// Camera, lights and look of a scene's renders as the scene file states them (the "render" block).
// Colours are linear-ish RGB in [0, 1]; lengths in metres; angles in degrees.
#include "core/types.h"

namespace kf {
class Block;

struct CameraSpec {
  Vec3 eye = Vec3(0, 5, 10);    // metres, world frame, Y up
  Vec3 target = Vec3::Zero();   // point looked at
  Vec3 up = Vec3::UnitY();
  double fov = 40.0;            // vertical field of view, degrees
};

struct RenderSpec {
  int width = 640, height = 480;      // pixels
  bool has_camera = false;            // false: frame the trajectory's bounding box automatically
  CameraSpec camera;                  // used when has_camera
  double fov = 40.0;                  // vertical fov of the automatic camera, degrees
  Vec3 light_direction = Vec3(0.45, 1.0, 0.35).normalized();  // towards the sun (unit)
  double light_angle = 6.0;           // angular diameter of the sun, degrees (soft shadows, Embree)
  double ambient = 0.8;               // sky light relative to the sun
  int samples = 16;                   // Embree samples per pixel
  bool ground = true;                 // draw the ground plane (y = 0, or the ground collider)
  double agent_size = 0.6;            // agent arrowhead length, metres
  int checker = 8;                    // cloth checker squares along the width (0: plain)
  Vec3 background = Vec3(0.87, 0.91, 0.96);
  Vec3 ground_color = Vec3(0.80, 0.79, 0.76);
  Vec3 agent_color = Vec3(0.16, 0.30, 0.62);
  Vec3 highlight_color = Vec3(0.90, 0.16, 0.10);  // circled agent of a race
  Vec3 target_color = Vec3(0.10, 0.58, 0.22);     // keyframe polygons, arch targets
  Vec3 path_color = Vec3(0.95, 0.55, 0.08);       // centre-of-mass path
  Vec3 cloth_front = Vec3(0.82, 0.24, 0.20);
  Vec3 cloth_back = Vec3(0.95, 0.82, 0.45);
  Vec3 collider_color = Vec3(0.62, 0.64, 0.70);
  Vec3 body_color = Vec3(0.87, 0.67, 0.54);       // meshes of RUN_DIR/meshes.bin (skin)
};

// Reads the "render" block; unknown keys are errors. Throws InputError.
RenderSpec parse_render_spec(Block& b);

}  // namespace kf
