#pragma once
// The coarsest level of cloth forces: one acceleration a (3 numbers) pushing every particle by m_i a at every
// controlled step, a wind or a tilt of gravity, the way a user pushes a whole sheet. Levenberg–Marquardt on a
// (opt/few_variable_fit.h, a Jacobian is six flights) finds the push that best places the keyframes; the
// strategy starts the first stage of a sheet's forces from it (opt/strategy.cpp), where L-BFGS on the lattice
// or on every particle stalls far from a solution of this kind (a sheet grazing a body's contact layer).
#include <string>
#include <vector>

#include "core/types.h"
#include "opt/few_variable_fit.h"
#include "opt/problem.h"
#include "scene/scene.h"

namespace kf {

// The controls of `problem` (per-step or per-frame forces, any basis) that give every particle m_i a at every
// step they control (a lattice's least-squares fit of it). Empty for initial-velocity controls.
VecX uniform_push_controls(Problem& problem, const Vec3& a);

struct UniformPush {
  Vec3 a = Vec3::Zero();  // the push found, m/s²
  VecX z;                 // the problem's controls for it (empty: nothing fitted)
  double start_cost = 0;  // ½‖r‖² of the placed keyframes (weighted as φ weighs them) with no push
  double cost = 0;        // and with the push a
  double worst_miss = 0;  // the largest keyframe distance under the push, in tolerances
  int simulated = 0;      // flights, Jacobians' included
  std::vector<double> costs;  // the fit's cost at the start and after each accepted step
  FitStop stop = FitStop::kNoResiduals;
};

// The strategy's fit (opt/strategy.cpp's push_uniformly_first): steps and differences in m/s², within half of
// the scene's gravity, keyframes met at a quarter of their tolerance, the paying test on; at most `flights`.
FewFitOptions uniform_push_options(const Scene& scene, int flights);

// Levenberg–Marquardt on a from no push. `problem` must have force controls; its last rollout is left at an
// arbitrary point and the system's step schedule released.
UniformPush fit_uniform_push(Problem& problem, const Scene& scene, const FewFitOptions& options);

// One line for the run's log: how the fit ended, its flights, the push and the worst miss reached.
std::string describe(const UniformPush& push);

}  // namespace kf
