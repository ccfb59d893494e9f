#pragma once
// A rectangular cloth and its colliders as the scene file states them.
// Particle (i, j), i = 0..nx-1 along the width, j = 0..ny-1 along the height, has index j*nx + i.
#include <string>
#include <vector>

#include "core/types.h"

namespace kf {
class Block;

// A collider the cloth is pushed out of by stiff springs inside `thickness`.
struct ColliderSpec {
  std::string type;              // "ground" | "sphere" | "torus"
  Vec3 center = Vec3::Zero();    // sphere, torus centre; ground: a point on the plane
  Vec3 axis = Vec3::UnitY();     // ground normal; torus symmetry axis (unit)
  double radius = 0.5;           // sphere radius; torus major radius (centre of tube)
  double tube_radius = 0.05;     // torus minor radius
  double thickness = 0.01;       // contact springs act within this distance of the surface
  double stiffness = 1e4;        // N/m
};

struct ClothSpec {
  int nx = 16, ny = 16;
  std::vector<ColliderSpec> colliders;
};

ClothSpec parse_cloth_spec(Block& b);

}  // namespace kf
