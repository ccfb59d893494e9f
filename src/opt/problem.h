#pragma once
// The optimisation problem φ(z): simulate under the controls z, sum the keyframe terms and the control
// effort, and get dφ/dz from one adjoint pass.
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "adjoint/rollout.h"
#include "opt/controls.h"
#include "opt/objective_terms.h"
#include "scene/scene.h"
#include "sim/system.h"

namespace kf {

class Problem : public StateCost {
 public:
  // `time` may differ from the scene's (a finer or coarser substep count); keyframes stay on frames.
  Problem(const Scene& scene, const TimeSpec& time, System& sys);

  int size() const { return controls_.size(); }
  const Controls& controls() const { return controls_; }
  const TimeSpec& time() const { return time_; }
  System& system() { return sys_; }
  VecX initial_guess() const { return controls_.initial_guess(); }
  // A physically modest size of one control variable, what an optimiser's first step may change it by:
  // the mean particle's weight under standard gravity (N) for forces on cloth, its mass times 1 m/s^2 for
  // forces on a flock, 1 m/s for initial velocities.
  double control_scale() const;

  // φ(z); when grad is given, also dφ/dz. A simulation that diverges gives a large finite φ that grows
  // away from the last good point (so a line search backs off) and never NaN.
  double evaluate(const VecX& z, VecX* grad);
  bool last_diverged() const { return diverged_; }
  // The value (and gradient) evaluate gives a point that diverged, without simulating z: for a trial the
  // optimiser already knows to refuse. Counts as a diverged evaluation.
  double refuse(const VecX& z, VecX* grad) {
    diverged_ = true;
    return diverged_objective(z, grad);
  }

  // Adjoint checkpointing (scene key optimizer.checkpoint_every): evaluations with a gradient keep
  // every k-th state and recompute the others in the backward pass; 0 keeps every state. The gradient
  // is the same bit for bit either way. Evaluations without a gradient always keep every state.
  void set_checkpoint_every(int k) { checkpoint_every_ = k; }
  int checkpoint_every() const { return checkpoint_every_; }
  // Bytes the rollout of an evaluation with a gradient may hold (0: no limit): with checkpoint_every 0,
  // one whose estimate passes it is checkpointed (RolloutOptions::memory_budget). rollout().every tells.
  void set_memory_budget(std::size_t bytes) { memory_budget_ = bytes; }
  std::size_t memory_budget() const { return memory_budget_; }

  // Each keyframe term's weight is multiplied by scales[k] (scene.objectives order; empty: all 1), so a
  // stage may press on keyframes the scene's weights let the effort trade away (opt/keyframe_weights.h);
  // a scale of 0 leaves the keyframe out (a stage steering the keyframes before it, opt/windows.h).
  void set_weight_scales(std::vector<double> scales);
  const std::vector<double>& weight_scales() const { return scales_; }

  // Forces of the steps before the controls' first step (forces[n] for step n, 3p each; fewer: no force on
  // the rest): what earlier stages found there, held while a window later in time is optimised. They are
  // not variables and their effort is not counted.
  void hold_forces(std::vector<VecX> forces);
  const std::vector<VecX>& held_forces() const { return held_; }
  // The force step n gets under z: a held force before the controls' first step, else the controls'.
  void force_at(const VecX& z, int n, VecX& u) const;

  // Values of each term (keyframe terms by name, then "effort") at the last evaluated point, weighted as φ
  // sums them (with the weight scales).
  const std::vector<std::pair<std::string, double>>& breakdown() const { return breakdown_; }
  // The states of the last evaluated point (valid unless it diverged; with checkpointing and a
  // gradient only the kept ones, see Rollout::kept).
  const Rollout& rollout() const { return rollout_; }

  // StateCost: keyframe terms at the steps of their frames.
  bool active(int n) const override;
  double eval(int n, const VecX& x, const VecX& v, VecX& gx, VecX& gv) const override;

 private:
  // The steps of evaluate: φ (and dφ/dz) of a rollout that did not diverge, adding to `phi`; false if
  // either is not finite. The bowl evaluate gives instead for a point that diverged.
  bool objective_of_rollout(const VecX& z, VecX* grad, const StepControl& u_at, long double& phi);
  double diverged_objective(const VecX& z, VecX* grad);
  // Term k's value and gradient (added to gx, gv), times its weight scale.
  double eval_term(int k, const VecX& x, const VecX& v, VecX& gx, VecX& gv) const;

  TimeSpec time_;
  System& sys_;
  VecX v0_scene_, x0_;  // the scene's initial state, read once; controls_ is built from it
  Controls controls_;
  std::vector<std::unique_ptr<ObjectiveTerm>> terms_;
  std::vector<std::vector<int>> terms_at_step_;  // term indices per step
  std::vector<double> scales_;                   // per term; empty: all 1
  std::vector<VecX> held_;                       // forces of steps before the controls' first (hold_forces)
  mutable VecX gx_term_, gv_term_;               // one scaled term's gradient, before it is added
  VecX v0_;
  VecX u_;  // control force of the step being simulated
  int checkpoint_every_ = 0;
  std::size_t memory_budget_ = 0;
  VecX dx0_, dv0_;
  VecX dz_effort_;  // the effort's gradient, kept: a fresh vector of every control faulted in its pages each time
  Rollout rollout_;
  bool diverged_ = false;
  bool have_good_ = false;
  VecX z_good_;
  double phi_good_ = 0;
  std::vector<std::pair<std::string, double>> breakdown_;
};

}  // namespace kf
