#pragma once
// Keyframes and other objective terms as the scene file states them (validated, not yet evaluated).
#include <optional>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "core/types.h"
#include "scene/solver_choices.h"

namespace kf {

// One struct a keyframe type, each with its scene-file name; parsed through one table (scene.cpp) and
// consumed with std::visit, so a new type is named by the compiler at every site that must handle it
// (its objective term, its figure measures, its drawing). See src/README.md.

// ½w Σ‖x_i − t_i‖² over the listed particles (all when none are listed).
struct PositionKeyframe {
  static constexpr const char* kName = "position";
  std::vector<Vec3> targets;  // metres: one per listed particle, or one for all
};
// ½w Σ‖v_i − t_i‖².
struct VelocityKeyframe {
  static constexpr const char* kName = "velocity";
  std::vector<Vec3> targets;  // m/s: one per listed particle, or one for all
};
// ½w‖x̄ − c‖², x̄ the mean position of the listed particles.
struct CenterOfMassKeyframe {
  static constexpr const char* kName = "center_of_mass";
  Vec3 target = Vec3::Zero();  // metres
};
// Flocks: agents outside a ground polygon (x, z) are pulled to at least `margin` inside it.
struct ShapeKeyframe {
  static constexpr const char* kName = "shape";
  std::vector<Vec2> polygon;  // closed polygon on the ground, (x, z), metres
  double margin = 0;          // metres
  // Filling the region: every point of a grid of `spacing` inside the polygon should have an agent within
  // `radius` (default: the flock's avoidance radius; spacing default radius / 2). `coverage_weight` 0 leaves
  // the term off; the figure measure coverage_fraction uses radius and spacing either way. The penalty of a
  // point is ½w (2r (d − r))², d its distance to the nearest agent (softened): in m², like the inside term's.
  double coverage_weight = 0;
  double coverage_radius = 0;   // metres
  double coverage_spacing = 0;  // metres
  std::vector<std::vector<Vec2>> holes;  // closed polygons inside `polygon`, left out of the region (a ring's inside)
};
// Cloth: particles pulled onto a cylinder (an arch).
struct ArchKeyframe {
  static constexpr const char* kName = "arch";
  Vec3 axis_point = Vec3::Zero();  // a point on the cylinder axis
  Vec3 axis = Vec3::UnitZ();       // unit axis direction
  double radius = 1.0;             // cylinder radius, metres
};

// Cloth: ½w (ȳ − h)², ȳ the mean height (y) of the listed particles: lifted or laid down, anywhere.
struct HeightKeyframe {
  static constexpr const char* kName = "height";
  double height = 0;  // metres
};

using ObjectiveKind =
    std::variant<PositionKeyframe, VelocityKeyframe, CenterOfMassKeyframe, ShapeKeyframe, ArchKeyframe, HeightKeyframe>;

// Where an objective came from: the scene's "objectives" array, or a block that adds its own (the
// character's "end_target" appends a position and a velocity keyframe at the last frame).
enum class ObjectiveSource { kScene, kEndTarget };

struct ObjectiveSpec {
  ObjectiveKind kind;
  int frame = 0;                // keyframe (frame index, 0..frames)
  double weight = 1.0;
  std::vector<int> particles;   // empty: all particles
  ObjectiveSource source = ObjectiveSource::kScene;
};

// The scene-file name of the objective's type ("position", ...).
inline const char* type_name(const ObjectiveSpec& o) {
  return std::visit([](const auto& k) { return std::decay_t<decltype(k)>::kName; }, o.kind);
}

// The control parameterisation (scene key controls.kind, named as in the scene file by control_kind_name).
enum class ControlKind {
  kPerStep,
  kPerFrame,
  kInitialVelocity,
  kInitialRigidVelocity,
  kInitialLatticeVelocity,
  kPerFrameLattice  // per-frame forces interpolated from a 3 x 3 lattice over the sheet (a coarse stage)
};

inline const char* control_kind_name(ControlKind k) {
  constexpr const char* kNames[] = {"per_step", "per_frame", "initial_velocity", "initial_rigid_velocity",
                                    "initial_lattice_velocity", "per_frame_lattice"};
  return kNames[int(k)];
}

// The effort weight initial-velocity controls default to.
constexpr double kInitialVelocityAlpha = 1e-6;

// The defaults are the scene file's: a scene without controls.kind gets per_frame forces, what every shipped
// scene asks for (tests/results/shots/README.md, "One default controls.kind"); the parser reads them here.
struct ControlSpec {
  ControlKind kind = ControlKind::kPerFrame;
  double alpha = 1e-4;  // weight of the control effort ½α‖u‖² (forces' default; see kInitialVelocityAlpha)
  // Forces act from this frame on (per_step / per_frame); earlier steps are uncontrolled. A blend whose
  // start flails against the body is steered over its last frames, where the gradient stays finite.
  int from_frame = 0;
};

// One stage of continuation: optimise at this many substeps per frame, optionally over a coarser control
// parameterisation. With initial-velocity control a stage may optimise the rigid throw (6 variables) first:
// the next stage starts from the per-particle velocities it gives, so the stiff springs begin unexcited.
struct StageSpec {
  int substeps = 1;
  int max_evaluations = 100;
  std::optional<ControlSpec> controls;  // empty: the scene's controls
};

// optimizer.split_schedule and optimizer.strategy, read once here (their names stay in src/scene/).
enum class SplitSchedule { kHeld, kAdaptive };
enum class StagingStrategy { kAuto, kSingle };

struct OptimizerSpec {
  int max_evaluations = 300;  // each one forward + one adjoint pass
  double ftol_rel = 1e-8;
  double max_seconds = 0;  // 0: no limit
  int memory = 10;         // L-BFGS vectors
  std::vector<StageSpec> schedule;  // empty: one stage at the scene's substeps
  int checkpoint_every = 0;  // adjoint pass keeps every k-th state and recomputes the rest; 0: keep all
  // Memory budget of a run (GB = 1e9 bytes; 0: half the machine's memory). With checkpoint_every 0, the
  // adjoint is checkpointed when keeping every step is estimated to pass it.
  double max_memory = 0;
  // Fresh L-BFGS starts from the best point after a stalled line search, within each stage's budget
  // (an approximate gradient, or a held split pattern gone stale, stalls the line search long before the
  // objective stops falling).
  int restarts = 5;
  // Cloth: "held" simulates each stage's start (and each restart's) once and repeats the split pattern its
  // energy check chose (ClothSystem::hold_schedule), so φ has no jumps where the check flips between
  // trial points; "adaptive" checks every step of every evaluation.
  SplitSchedule split_schedule = SplitSchedule::kHeld;
  // Cloth adjoint (scene/solver_choices.h): exact (the transpose of the step's Jacobian) or swap (the paper's
  // integrator swap).
  AdjointKind adjoint = AdjointKind::kExact;
  // How the run is split into stages when no schedule is given (opt/windows.h): "auto" keeps every
  // gradient short on cloth (forces over windows grown backwards from the last keyframe when the gradient
  // grows across the horizon; a rigid throw before per-particle initial velocities), "single" optimises
  // the scene's controls in one stage.
  StagingStrategy strategy = StagingStrategy::kAuto;
  int window_frames = 5;  // the first window's length in frames; each next window is twice as long
  double window_growth = 1e3;  // windows when the start's force gradient grows more than this (or in contact: opt/windows.h)
  // RMS change per control variable of L-BFGS's first trial step (N for forces, m/s for velocities); a
  // steeper start is scaled down to it. < 0: automatic (the mean particle's weight, or 1 m/s); 0: off.
  double first_step = -1;
  // Strategy auto, initial_velocity controls: rigid throws simulated (forward only) before the rigid
  // stage, which starts from the best (opt/throw_search.h). < 0: automatic (automatic_throw_count); 0: off.
  int throw_search = -1;
  // Stop as soon as an evaluation's result meets every keyframe's tolerance (the tolerances report.json
  // judges by, opt/diagnosis.h), instead of polishing it until the objective stops changing. On by default:
  // a run polishing keyframes already met spends time that decides nothing the judgement sees; a scene that
  // wants more than its tolerances (the paper's figures) turns it off.
  bool stop_when_reached = true;
  // Soft keyframes: the scene's weights decide how close a keyframe comes, traded against the effort. Off:
  // a run that ends early with a keyframe outside its tolerance raises that keyframe's weight and goes on
  // (opt/keyframe_weights.h).
  bool soft_keyframes = false;
  // A uniform push (opt/uniform_push.h) fitted before the first window of a sheet's forces, within half of
  // gravity; the first window starts from it when it pays (tests/results/reachable/README.md, "The uniform push
  // as a default").
  bool uniform_push = true;
};

}  // namespace kf
