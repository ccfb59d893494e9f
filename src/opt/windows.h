#pragma once
// The stages a run optimises in. An exact gradient of cloth in contact, or released flat, grows by orders
// of magnitude per frame: across a long horizon it describes nothing an optimiser can use. So, unless the
// scene gives its own schedule or asks for optimizer.strategy "single", cloth is optimised in stages that
// keep each gradient short:
//  - forces (per_step / per_frame), when the gradient at the start grows across the horizon by more than
//    optimizer.window_growth (the largest frame's force gradient over that of the last frame before the
//    last keyframe), or per-frame forces on a sheet with colliders or a body at all, act first over the
//    last `window_frames` frames before the last keyframe (with half the evaluations), then over windows
//    twice, four times ... as long, down to controls.from_frame; each stage starts from the forces
//    the last one found (new frames without force), so a longer window can only improve on it. Below the
//    threshold, one stage, and the windows if it ends early with evaluations left. Per-frame
//    forces act on a 3 x 3 lattice over the sheet in every window; after each keyframe's lattice windows, per
//    particle over that keyframe's first (shortest) window, the forces before it held (a per-particle
//    gradient over the whole horizon is amplified where the window's is tame: its line search stalls at once);
//    then per particle over the whole horizon.
//    With keyframes at several frames the windows go in time order: those grown back from the earliest
//    keyframe (later ones left out, so it is met first), then those grown back from the next down to the
//    keyframe before it (the forces before the window held as found), and so on; the last stage optimises
//    every keyframe over the whole horizon. Grown back from the last keyframe alone, the windows reach an
//    early keyframe only when they are long, where their line searches stall and leave it uncontrolled;
//    in contact a per-particle gradient is ruled by the few particles touching, and its line search stalls
//    where a force on the sheet as a whole still moves it (a cape on a swinging body). A tame gradient (a sheet in free flight) keeps one stage.
//  - per-particle initial velocities start from the best rigid throw (six numbers; ring-toss.json's stages),
//    found by a search over throws and then L-BFGS, bent by a 3 x 3 lattice of velocities over the sheet
//    (27 numbers, smooth over it) before every particle gets its own. A flight of more than 12000
//    particle-steps shares fewer of the evaluations (opt/throw_search.h's large_flight_share to the power 1.5).
// Flocks, whose gradients stay tame, run in one stage.
#include <string>
#include <vector>

#include "opt/problem.h"
#include "scene/scene.h"

namespace kf {

// A stage's keyframes: those up to this frame count (later ones are left out), or all.
constexpr int kAllKeyframes = -1;

struct StagePlan {
  std::vector<StageSpec> stages;  // at least one; the last optimises the scene's own controls
  std::vector<int> judged_until;  // per stage, the frame its keyframes count up to (missing: kAllKeyframes)
  // Per stage, the factor on every friction coefficient of the scene it simulates (missing: 1): the windows
  // of a scene with friction run first with it eased, then again at the scene's (opt/friction_continuation.h).
  std::vector<double> friction_scales;
  double growth = 0;              // the force gradient's growth at the start (0: not measured)
  int throw_search = 0;           // rigid throws simulated before the first (rigid) stage (opt/throw_search.h)
  // The strategy staged the run (windows, or a rigid throw first), or the scene is a flock: an automatic
  // optimizer.first_step is then the problem's control_scale(); elsewhere it is off. A flock's whole
  // gradient grows with its size, and a first trial step that long herds a crowd into a dense band it never leaves.
  bool scaled_first_step = false;
  // One stage of forces whose start is tame: when it ends early (its line search stalls, or it converges)
  // with evaluations left, the run optimises again in windows from no force with what is left
  // (window_stages) and keeps the better result. A tame start may roughen later, and one stage over the
  // whole horizon may settle on forces far costlier than windows find (a flag released in its plane).
  bool windows_on_early_end = false;
  // optimizer.uniform_push, on windows of forces on a sheet (per step or per frame): the first window starts
  // from the uniform push that best places the keyframes (opt/uniform_push.h), when the fit paid and stayed
  // within half of gravity (push_uniformly_first in opt/strategy.cpp). Not in one tame stage: started from a
  // push, its L-BFGS lost hang-edge-6 and hang-points-6.
  bool uniform_push = false;
  std::string why;                // one line: the plan and what chose it
  // A large flight's stages share fewer evaluations than optimizer.max_evaluations: how many (0: not scaled).
  int scaled_budget = 0;
};

// The stages of `scene`. Measuring the growth costs one simulation and its adjoint pass.
StagePlan plan_stages(const Scene& scene);

// The windows for per-step or per-frame forces, sharing `budget` evaluations: grown back from the last
// keyframe (the first window half of them), or, with keyframes at several frames, grown back from each
// keyframe in time order (the first window of each keyframe sharing half). Per-frame forces' windows are on
// the lattice, each keyframe's followed by a per-particle window over its first window's frames. `judged_until`, when given,
// gets each stage's keyframe frame (kAllKeyframes: every keyframe counts).
std::vector<StageSpec> window_stages(const Scene& scene, int budget, std::vector<int>* judged_until = nullptr);

// Friction eased in (opt/friction_continuation.h): a plan of windows on a scene with friction becomes the
// windows with every friction coefficient times `scale` (< 1) on 40 % of the budget, then the windows at the
// scene's friction, each starting from the forces the eased ones found. Not part of plan_stages: on the
// generated suite's failing friction scenes it won nothing (tests/results/reachable/friction/). Leaves
// other plans (one stage, a throw, no friction, scale >= 1) as they are.
void ease_friction(const Scene& scene, double scale, StagePlan& plan);

// The distinct frames of the scene's keyframes that forces from controls.from_frame can move, in order.
std::vector<int> keyframe_frames(const Scene& scene);

// Per-frame force controls' gradient at z: the largest frame's gradient norm over the norm of frame
// `reference`'s (infinite when that is zero and another is not; 1 when all are zero).
double gradient_growth(Problem& problem, const VecX& z, int reference);

}  // namespace kf
