#include "scene/render_spec.h"

#include <Eigen/Geometry>

#include "scene/params.h"

namespace kf {

RenderSpec parse_render_spec(Block& b) {
  RenderSpec s;
  s.width = b.integer("width", s.width, 16, 8192);
  s.height = b.integer("height", s.height, 16, 8192);
  if (auto c = b.optional_child("camera")) {
    s.has_camera = true;
    s.camera.eye = c->vec3("eye");
    s.camera.target = c->vec3("target");
    s.camera.up = c->vec3("up", s.camera.up, -1e3, 1e3);
    s.camera.fov = c->number("fov", s.camera.fov, 1.0, 170.0);
    if ((s.camera.eye - s.camera.target).norm() < 1e-9) c->fail("target", "expected a point away from \"eye\"");
    if (s.camera.up.norm() < 1e-9 || s.camera.up.cross(s.camera.eye - s.camera.target).norm() < 1e-9)
      c->fail("up", "expected a direction not parallel to the view direction");
    s.camera.up.normalize();
    c->finish();
  }
  s.fov = b.number("fov", s.fov, 1.0, 170.0);
  s.light_direction = b.vec3("light_direction", s.light_direction, -1e3, 1e3);
  if (s.light_direction.norm() < 1e-9) b.fail("light_direction", "expected a non-zero direction");
  s.light_direction.normalize();
  s.light_angle = b.number("light_angle", s.light_angle, 0.0, 90.0);
  s.ambient = b.number("ambient", s.ambient, 0.0, 10.0);
  s.samples = b.integer("samples", s.samples, 1, 4096);
  s.ground = b.boolean("ground", s.ground);
  s.agent_size = b.number("agent_size", s.agent_size, 1e-3, 100.0);
  s.checker = b.integer("checker", s.checker, 0, 1000);
  s.background = b.vec3("background", s.background, 0.0, 1.0);
  s.ground_color = b.vec3("ground_color", s.ground_color, 0.0, 1.0);
  s.agent_color = b.vec3("agent_color", s.agent_color, 0.0, 1.0);
  s.highlight_color = b.vec3("highlight_color", s.highlight_color, 0.0, 1.0);
  s.target_color = b.vec3("target_color", s.target_color, 0.0, 1.0);
  s.path_color = b.vec3("path_color", s.path_color, 0.0, 1.0);
  s.cloth_front = b.vec3("cloth_front", s.cloth_front, 0.0, 1.0);
  s.cloth_back = b.vec3("cloth_back", s.cloth_back, 0.0, 1.0);
  s.collider_color = b.vec3("collider_color", s.collider_color, 0.0, 1.0);
  s.body_color = b.vec3("body_color", s.body_color, 0.0, 1.0);
  b.finish();
  return s;
}

}  // namespace kf
