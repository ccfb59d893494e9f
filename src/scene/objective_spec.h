#pragma once
// Keyframes and other objective terms as the scene file states them (validated, not yet evaluated).
#include <string>
#include <vector>

#include "core/types.h"

namespace kf {

struct ObjectiveSpec {
  // "position", "velocity": per-particle targets; "center_of_mass": one target for the group;
  // "shape": agents outside a ground polygon (x, z) are pulled to it; "arch": cloth onto a cylinder.
  std::string type;
  int frame = 0;           // keyframe (frame index, 0..frames)
  double weight = 1.0;
  std::vector<int> particles;   // empty: all particles
  std::vector<Vec3> targets;    // position/velocity: one per listed particle (or one for all); com: one
  std::vector<Vec2> polygon;    // shape: closed polygon on the ground, (x, z), metres
  double margin = 0;            // shape: agents are pulled at least this far inside (m)
  Vec3 axis_point = Vec3::Zero();  // arch: a point on the cylinder axis
  Vec3 axis = Vec3::UnitZ();       // arch: unit axis direction
  double radius = 1.0;             // arch: cylinder radius, metres
};

struct ControlSpec {
  std::string kind = "per_step";  // "per_step" | "per_frame" | "initial_velocity" | "initial_rigid_velocity"
  double alpha = 1e-4;            // weight of the control effort ½α‖u‖²
};

// One stage of coarse-to-fine continuation: optimise at this many substeps per frame.
struct StageSpec {
  int substeps = 1;
  int max_evaluations = 100;
};

struct OptimizerSpec {
  int max_evaluations = 300;  // each one forward + one adjoint pass
  double ftol_rel = 1e-8;
  double max_seconds = 0;  // 0: no limit
  int memory = 10;         // L-BFGS vectors
  std::vector<StageSpec> schedule;  // empty: one stage at the scene's substeps
  int checkpoint_every = 0;  // adjoint pass keeps every k-th state and recomputes the rest; 0: keep all
  // Fresh L-BFGS starts from the best point after a stalled line search, within each stage's budget
  // (an approximate gradient stalls the line search long before the objective stops falling).
  int restarts = 0;
  // Cloth adjoint: "exact" (the transpose of the step's Jacobian) or "swap" (the paper's integrator swap).
  std::string adjoint = "exact";
};

}  // namespace kf
