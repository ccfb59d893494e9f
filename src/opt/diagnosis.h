#pragma once
// Whether an optimisation reached its keyframes and, when it did not, why and what to change.
//
// Each keyframe is judged by its measure against its kind's tolerance (opt/keyframes/); its miss is
// the error over the tolerance, so a miss of at most 1 is met. The run fails (keyframe optimize exits with
// kExitNotReached) when some keyframe is not met; the outcome tells a near miss (progress, every keyframe
// within kFarMiss tolerances) from a far one and from no meaningful progress (the keyframe terms of φ fell
// by less than half). The cause comes from measurements at the start: how much the motion amplifies a
// perturbation on its way to the keyframe (the gradient of φ with respect to a force held over each frame,
// from one adjoint pass) and how noisy φ is under perturbations of 1e-9 (a bifurcation such as a flat sheet
// released in its own plane).
#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/trajectory.h"
#include "opt/keyframes/keyframe_kind.h"
#include "scene/scene.h"

namespace kf {

// A keyframe whose error is more than this many tolerances is far from its target (outcome "not_reached"
// rather than "near").
constexpr double kFarMiss = 3.0;

// One keyframe (objective) of the scene, judged before (the uncontrolled run) and after the optimisation.
struct KeyframeJudgement {
  std::string name;        // "center_of_mass@30"
  int frame = 0;
  bool judged = false;     // false: no tolerance for this kind (velocity keyframes); never a miss
  double miss_before = 0;  // error / tolerance: <= 1 is met
  double miss_after = 0;
  std::string error_before, error_after;  // the error in the measure's unit ("12.30 cm", "inside 0.620")
  std::string tolerance;                  // "1.20 cm", "inside >= 0.95 and coverage >= 0.9"
  const char* error_phrase = "";          // how the error reads after it in a line (" from its target")
  bool from_target = true;                // the error is how far from a target; false: a state ("inside 0.620")
  bool met() const { return !judged || miss_after <= 1.0; }
  nlohmann::json to_json() const;
};

// Judges scene.objectives[i] by its measures in the uncontrolled run (before[i]) and in the result
// (after[i]), each from measure_keyframes (opt/keyframes/keyframe_kind.h): each kind's file states its
// tolerance.
std::vector<KeyframeJudgement> judge_keyframes(const Scene& scene, const std::vector<KeyframeMeasure>& before,
                                               const std::vector<KeyframeMeasure>& after);

// Whether each keyframe of the scene is unmet in a run's frames (the stop rule's judgement).
std::vector<bool> keyframes_unmet(const Scene& scene, const Trajectory& frames);

// How the uncontrolled motion propagates perturbations to the keyframes, measured at the start.
struct Sensitivity {
  // |∂φ/∂u_f| for a force u_f on every particle held over frame f, f = 0 .. keyframe - 1, at no control.
  std::vector<double> gradient_by_frame;
  int keyframe = 0;               // the last keyframe's frame
  double growth = 1;              // max_f gradient_by_frame[f] / gradient_by_frame[keyframe - 1]
  double growth_beyond_free = 1;  // the same over the growth of free flight, (keyframe − f): ~1 when smooth
  int grows_from_frame = 0;       // the last frame whose gradient is within 10x of the largest
  double phi = 0;                 // φ at the start (force controls held over frames, none applied)
  double phi_noise = 0;           // φ's spread under perturbations of 1e-9 of the controls
  double relative_noise() const { return phi != 0 ? phi_noise / std::abs(phi) : 0.0; }
  bool noisy() const { return relative_noise() > 1e-6; }
  bool amplifying() const { return growth_beyond_free > 1e3; }
  nlohmann::json to_json() const;
};

// Simulates the scene at `time` (its own system, built here) under per-frame force controls and takes one
// gradient and six more evaluations of φ. Keyframes at frame 0 only: an empty gradient_by_frame.
// checkpoint_every and memory_budget (bytes) as the run's Problem takes them (0: the scene's spacing, no
// limit), so the gradient holds no more memory than the run's own; the result is the same bit for bit.
Sensitivity measure_sensitivity(const Scene& scene, const TimeSpec& time, int checkpoint_every = 0,
                                std::size_t memory_budget = 0);

// φ along the negative gradient at the point an optimisation stopped: at distances t = 1e-6 .. 1 times
// φ / |g| (where the linear prediction φ - t |g| reaches 0), log-spaced. On smooth ground φ falls as its
// gradient predicts over a fair part of that distance; where contact switches or a held split pattern has
// gone stale, it does so only over a sliver, and a line search there stalls however good the gradient.
struct DescentProbe {
  double phi = 0, grad_norm = 0;
  std::vector<double> steps, phis;  // t (control units) and φ there
  // The largest t / (φ / |g|) up to which every point fell at least half as much as predicted
  // (0: not even the first; 1: not measured or smooth throughout).
  double linear_fraction = 1;
  bool rough() const { return linear_fraction < 1e-3; }
  double reach() const { return grad_norm > 0 ? phi / grad_norm : 0.0; }  // φ / |g|, control units
  nlohmann::json to_json() const;
};
class Problem;
DescentProbe probe_descent(Problem& problem, const VecX& z);

// What the optimiser's run shows besides its keyframes.
struct RunFacts {
  std::string status;                // why the last stage stopped
  bool budget = false;               // it stopped at an evaluation or time limit
  int scaled_budget = 0;             // a large flight's plan: the evaluations it gave (0: optimizer.max_evaluations)
  int max_evaluations = 0;           // optimizer.max_evaluations
  double keyframe_objective_start = 0;  // φ without the effort term, first and best evaluation
  double keyframe_objective_end = 0;
  double effort_end = 0;             // the effort term at the end
  double max_objective = 0;          // the largest φ any trial point gave
  double objective_start = 0;        // φ at the first evaluation
  double recent_improvement = 1;     // best φ at the end over the best φ 10 % of the evaluations earlier
  int evaluations = 0;
  DescentProbe descent;              // at the best point, when the keyframes were not reached
  bool flock = false;                // a flock's run: its causes and changes name agents, not sheets
  int unstable_trials = 0;           // evaluations whose simulation the system refused as unstable
  int diverged_trials = 0;           // evaluations whose simulation diverged (the unstable ones included)
  std::string fallback;              // why the run ended before its last stage's result (StrategyResult)
};

struct Diagnosis {
  bool reached = false;   // every judged keyframe met
  bool progress = false;  // the keyframe terms fell to at most half
  bool far = false;       // some keyframe misses by more than kFarMiss tolerances
  bool failed() const { return !reached; }
  std::string outcome;    // "reached", "near", "not_reached", "no_progress"
  std::string line;       // one line for the user: what happened, the cause, what to change
  nlohmann::json to_json() const;
};

// Evaluations a run stopped at its budget expects to need still, from its own progress: keyframe terms scale
// as the square of a miss, so bringing the worst miss (in tolerances) to 1 divides them by its square; at the
// rate φ fell over the last tenth of the run (RunFacts::recent_improvement) that takes log(miss²) / log(1 / rate)
// tenths. 0 when φ no longer fell or nothing is missed.
int expected_more_evaluations(const RunFacts& facts, double worst_miss);

Diagnosis diagnose(const std::vector<KeyframeJudgement>& keyframes, const Sensitivity& sensitivity,
                   const RunFacts& facts);

}  // namespace kf
