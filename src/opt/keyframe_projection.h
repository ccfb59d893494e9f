#pragma once
// Gauss–Newton onto a sheet's keyframes, for every control kind (initial velocities, forces per step or per
// frame, per particle or on the lattice). A sheet's keyframes are a few residuals (three numbers per placed
// particle or centre of mass) against hundreds or thousands of controls, and at the optimum of keyframes plus
// effort the effort may hold a reachable keyframe just outside its tolerance, where L-BFGS on φ spends its
// budget on the trade-off. Here the keyframes are what must hold: Levenberg–Marquardt on the residuals r
// alone with the minimum-norm step dz = −Jᵀ(JJᵀ + μI)⁻¹ r (the smallest change of the controls that the
// linearised flight says meets them), J from one adjoint pass per residual.
#include <atomic>
#include <cmath>
#include <string>
#include <vector>

#include "core/types.h"
#include "opt/problem.h"
#include "scene/scene.h"

namespace kf {

enum class ProjectionStop {
  kReached,        // every placed keyframe within ProjectionOptions::reach_share of its tolerance
  kStalled,        // the damping grew past any useful step, or a step changed the residuals by nothing
  kBudget,         // the passes allowed were spent
  kInterrupted,    // *stop was set
  kNotApplicable,  // not a sheet, a keyframe with weight places no particles (a velocity or a height) or none
                   // does, or a Jacobian (one adjoint pass per residual) would take more than half the passes
                   // allowed (a keyframe on every particle)
  kDiverged,       // the start itself diverged
  kFar,            // the start's worst keyframe is more than ProjectionOptions::near_limit tolerances off
};

struct ProjectionOptions {
  int max_passes = 200;      // forward simulations plus adjoint passes
  double reach_share = 0.5;  // done when every keyframe is within this share of its tolerance
  // Steps smallest in the smooth metric for per-particle controls (opt/projection_metric.h; the default),
  // else in plain control values.
  bool smooth = true;
  // The largest change of one control variable in one step, in Problem::control_scale() (1 m/s for initial
  // velocities, the mean particle's weight for forces).
  double max_step = 1.0;
  double near_limit = INFINITY;  // not started when the worst keyframe is more tolerances off than this
  // A refused trial shortens the step (to a third of its largest change, a trust region the next Jacobians
  // keep and widen while the model holds) besides raising the damping; else the damping alone rises
  // (Levenberg–Marquardt). Where the flight is linear only over a tenth of the Gauss–Newton step, the damping
  // takes many refused trials to get there.
  bool backtrack = false;
  // A keyframe on many particles as its moments plus the residual vector (opt/residual_sketch.h), a Jacobian
  // of about 31 adjoint passes; else three rows per particle.
  bool sketch = false;
  const std::atomic<bool>* stop = nullptr;
};

struct KeyframeProjection {
  VecX z;                    // the point with the nearest worst keyframe reached (the start when nothing helped)
  double start_worst = 0;    // the worst keyframe's distance over its tolerance at the start
  double worst = 0;          // and at z
  int iterations = 0;        // Jacobians formed
  int simulations = 0;       // forward simulations
  int adjoint_passes = 0;    // one per residual (or sketched row) per Jacobian
  int refused = 0;           // trial steps refused (the residuals grew): where the linear model fails
  double first_gain = NAN;   // the first trial's actual over predicted fall of ½‖r‖² (1: the model is exact)
  ProjectionStop stop = ProjectionStop::kNotApplicable;
  bool reached() const { return stop == ProjectionStop::kReached; }
  bool improved() const { return worst < start_worst; }
};

// From z (the problem's controls), at the problem's weight scales and the system's held step schedule. The
// problem's last rollout is left at an arbitrary point.
KeyframeProjection project_onto_keyframes(Problem& problem, const Scene& scene, const VecX& z,
                                          const ProjectionOptions& options);

// In turn: the keyframes `unmet` flags (per scene objective) alone, with half the passes, then every keyframe
// from there with the rest. A keyframe in sliding contact is a rough function of the throw: pressed together
// with one in free flight, its residuals spoil every step, where the one in flight is met alone in a Jacobian
// or two. start_worst is the unmet keyframes' at z (the met ones are within their tolerance), worst every
// keyframe's at the result.
KeyframeProjection project_unmet_then_all(Problem& problem, const Scene& scene, const VecX& z,
                                          const std::vector<bool>& unmet, const ProjectionOptions& options);

// One line for the run's log.
std::string describe(const KeyframeProjection& p);

}  // namespace kf
