#pragma once
// A rectangular cloth and its colliders as the scene file states them.
// Particle (i, j), i = 0..nx-1 along the width (u_axis), j = 0..ny-1 along the height (v_axis), has
// index j*nx + i. Named edges are by index: "bottom" is j = 0, "top" is j = ny-1, "left" is i = 0,
// "right" is i = nx-1 (so with v_axis = +Y the top edge is the highest row).
#include <filesystem>
#include <memory>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "core/types.h"
#include "scene/cloth_mesh.h"
#include "scene/solver_choices.h"

namespace kf {
class Block;

// Collider shapes, one struct each with its scene-file name; parsed through one table (cloth_spec.cpp) and
// consumed with std::visit (its collider in sim/cloth/collider.cpp, its drawing in
// render/geometry/frame_geometry.cpp). See src/README.md.
struct GroundShape {
  static constexpr const char* kName = "ground";
  Vec3 point = Vec3::Zero();    // a point on the plane
  Vec3 normal = Vec3::UnitY();  // unit, pointing to the free side
};
struct SphereShape {
  static constexpr const char* kName = "sphere";
  Vec3 center = Vec3::Zero();
  double radius = 0.5;  // metres
};
// A ring: the tube of radius tube_radius around a circle of radius `radius` about `axis`.
struct TorusShape {
  static constexpr const char* kName = "torus";
  Vec3 center = Vec3::Zero();
  Vec3 axis = Vec3::UnitY();  // symmetry axis (unit)
  double radius = 0.5;        // major radius (centre of the tube), metres
  double tube_radius = 0.05;  // minor radius, metres (less than radius)
};
// A rod with round ends: the points within `radius` of the segment from a to b.
struct CapsuleShape {
  static constexpr const char* kName = "capsule";
  Vec3 a = Vec3::Zero();    // one end of the axis segment, metres
  Vec3 b = Vec3::UnitX();   // the other end (distinct from a)
  double radius = 0.1;      // metres
};

// An oriented box with rounded edges and corners (a table, a shelf, a step): the points within `radius` of
// the box of `size` shrunk by `radius` on every side. Its surface is smooth, so the push out of it turns
// smoothly round an edge.
struct BoxShape {
  static constexpr const char* kName = "box";
  Vec3 center = Vec3::Zero();
  Vec3 size = Vec3(1, 1, 1);   // full extents along u_axis, v_axis and u_axis x v_axis, metres
  Vec3 u_axis = Vec3::UnitX();  // unit
  Vec3 v_axis = Vec3::UnitY();  // unit, perpendicular to u_axis
  double radius = 0.02;         // rounding of the edges, metres (at most half the smallest size)
};
// A finite flat panel (a table top, a wall panel) of no thickness: `width` along u_axis, `height` along
// v_axis. It pushes from both sides, away from the nearest point of the rectangle.
struct RectangleShape {
  static constexpr const char* kName = "rectangle";
  Vec3 center = Vec3::Zero();
  Vec3 u_axis = Vec3::UnitX();  // unit
  Vec3 v_axis = Vec3::UnitZ();  // unit, perpendicular to u_axis; the panel's normal is u_axis x v_axis
  double width = 1.0;           // metres
  double height = 1.0;          // metres
};

using ColliderShape = std::variant<GroundShape, SphereShape, TorusShape, CapsuleShape, BoxShape, RectangleShape>;

// A collider the cloth is pushed out of by stiff springs inside `thickness`, with smoothed Coulomb friction
// (sim/cloth/friction.h) against sliding along it.
struct ColliderSpec {
  ColliderShape shape;
  double thickness = 0.01;  // contact springs act within this distance of the surface (m)
  double stiffness = 1e4;   // N/m
  double friction = 0;      // Coulomb coefficient (0, the default: frictionless)
  double friction_velocity = 0.01;  // m/s: slip slower than this counts as sticking (viscous below it)
};

// The scene-file name of the collider's shape ("ground", ...).
inline const char* type_name(const ColliderSpec& c) {
  return std::visit([](const auto& s) { return std::decay_t<decltype(s)>::kName; }, c.shape);
}

// Contact of the sheet with itself (sim/cape/self_collider.h): particle pairs closer than `thickness` repel,
// with friction against their relative slip. A cape's comes from character.self.
struct SelfContactSpec {
  bool enabled = false;
  double thickness = 0.01;           // m (cloth.self's default: the grid's particle spacing)
  double stiffness = 500.0;          // N/m
  double friction = 0;               // Coulomb coefficient (0: frictionless)
  double friction_velocity = 0.01;   // m/s
};

struct ClothSpec {
  // cloth.mesh (scene/cloth_mesh_spec.h): the sheet is this mesh, particle i its vertex i; null: the grid
  // below, whose keys the scene then may not give.
  std::shared_ptr<const ClothMesh> mesh;
  bool mass_by_area = true;             // a mesh's particle masses: by the area of their faces (else even)
  int nx = 16, ny = 16;
  double width = 1.0, height = 1.0;     // metres, along u_axis and v_axis
  Vec3 origin = Vec3::Zero();           // position of particle (0, 0), metres
  Vec3 u_axis = Vec3::UnitX();          // unit direction of the width edge (i grows)
  Vec3 v_axis = Vec3::UnitY();          // unit direction of the height edge (j grows)
  double mass = 0.5;                    // total, kg, spread evenly over the particles
  std::vector<int> pins;                // pinned particle indices (sorted, unique; named sets expanded)
  double stretch = 500.0;               // structural (type-1) spring stiffness in tension, N/m
  double shear = 50.0;                  // diagonal (type-1) spring stiffness in tension, N/m
  double bend = 5.0;                    // bending (type-2, two edges) spring stiffness in tension, N/m
  double buckle_strain = 0.005;         // compressive strain at which a spring buckles (Choi-Ko onset)
  double buckle_stiffness = 0.1;        // post-buckling stiffness as a fraction of the tension stiffness
  double damping = 0.05;                // spring damping along structural and shear springs, N s/m
  double air_drag = 0.1;                // linear drag per unit mass, 1/s (f = -air_drag * m * v)
  Vec3 gravity = Vec3(0, -9.81, 0);     // m/s^2
  Vec3 velocity = Vec3::Zero();         // initial velocity of every free particle, m/s
  // Seeded out-of-plane offsets of the initial sheet, uniform in [-imperfection, imperfection] metres,
  // which the springs take as their rest shape (sim/cloth/imperfection.h); 0: exactly flat. On by default:
  // an exactly flat, symmetric sheet is a bifurcation whose gradient is round-off (opt/windows.h).
  double imperfection = 5e-4;
  int imperfection_seed = 1;
  double cg_tolerance = 1e-8;           // PCG stops when |r| <= cg_tolerance * |b| (filtered)
  bool cg_tolerance_stated = false;     // the scene gave cg_tolerance (else use_motion_tolerance may relax it)
  int cg_max_iterations = 1000;         // PCG failing to converge within this fails the step
  // auto (the cloth system picks by the sheet's size), incomplete_cholesky, multigrid, block_jacobi
  // (scene/solver_choices.h).
  CgPreconditioner cg_preconditioner = CgPreconditioner::kAuto;
  std::string solver = "pcg";           // "direct": sparse LDL^T per step, exact to round-off
  // "implicit": control forces enter the backward-Euler solve with the springs, which filters them (a
  // force against a stiff spring barely moves it within a step). "explicit": each substep adds h u / m to
  // the velocities after the solve, so a control reaches every mode of the sheet alike; an end-state
  // keyframe's stiff (stretch) modes then stop slowing the optimiser by the springs' stiffness squared.
  std::string control_integration = "implicit";
  // A step that gains energy is split in halves, at most this many times (0: never split).
  int max_halvings = 8;
  // Every contact's stiffness rises from 0 to full over this fraction of its thickness (ContactProfile);
  // 0: the linear penalty, whose stiffness jumps where contact begins.
  double contact_ramp = 0.5;
  // The strain over which a stretched spring's transverse stiffness T/s fades into the step's matrix
  // (BucklingSpring::transverse_ramp); below it part of that stiffness acts explicitly within the step.
  // Narrower: more of it implicit, so light particles on taut springs stop chattering (fewer PCG
  // iterations and split steps) but the sheet's motion is damped more (README, Cloth solver speed).
  double transverse_ramp = 0.05;
  // The step's implicitness: forces act at x + theta (x1 - x), v + theta (v1 - v) (the one-leg theta
  // method, linearised as backward Euler with step theta h). 1: backward Euler, which damps motion that
  // takes few steps a period; 0.5: implicit midpoint, no numerical damping; between: less damping than 1.
  // Below 1 the transverse stiffness needs a narrow transverse_ramp, or its explicit part grows.
  double theta = 1.0;
  std::vector<ColliderSpec> colliders;
  SelfContactSpec self;                 // cloth.self (off by default)
  bool self_stated = false;             // the scene gave a cloth.self block

  int particles() const { return mesh ? mesh->particles() : nx * ny; }
  bool direct_solver() const { return solver == "direct"; }
  bool explicit_controls() const { return control_integration == "explicit"; }
  bool block_jacobi() const { return cg_preconditioner == CgPreconditioner::kBlockJacobi; }
  int index(int i, int j) const { return j * nx + i; }
  // A run that takes no gradient (keyframe simulate) needs only the motion: unless the scene states
  // cg_tolerance, it solves to kMotionTolerance instead of the default, which is for gradients (their error
  // follows the tolerance). On the Blender anchor's 50 x 50 sheet a 1e-4 run ends as close to a 1e-12 run as
  // a 1e-8 run does, after 1,200 steps (tests/results/bench/solver_blender.csv); Blender's own cloth CG
  // stops at a relative residual of 1e-2, in single precision.
  static constexpr double kMotionTolerance = 1e-4;
  void use_motion_tolerance() {
    if (!cg_tolerance_stated) cg_tolerance = kMotionTolerance;
  }
};

// Reads the "cloth" block (every key range-checked, unknown keys are errors). "pins" is either an array
// of particle indices or one named set: "none", "top_edge", "bottom_edge", "left_edge", "right_edge",
// "top_corners", "bottom_corners", "corners" (a grid's), or a region (cloth_mesh_spec.h). `directory`: where
// the path of a cloth.mesh file starts (the scene file's directory).
ClothSpec parse_cloth_spec(Block& b, const std::filesystem::path& directory = {});

// The particle indices of a named pin set for an nx x ny cloth (sorted). Throws std::invalid_argument on
// an unknown name.
std::vector<int> named_pin_set(const std::string& name, int nx, int ny);

}  // namespace kf
