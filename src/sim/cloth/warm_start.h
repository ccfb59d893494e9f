#pragma once
// The starting guess of linear solves that come one step after another, each solution close to the last:
// the polynomial through the last solutions of consecutive steps (up to three, so quadratic), extrapolated
// one step on. A cloth sheet's velocity change and its adjoint change smoothly from step to step; on the
// pinned 50 x 50 sheet the quadratic guess saved forward and adjoint PCG iterations against the linear one,
// as the linear one did against the last solution alone.
// The guess depends only on the remembered solutions, so a rollout stays the same function of its inputs;
// save and restore carry the history across checkpoints.
#include "core/types.h"

namespace kf {

class WarmStart {
 public:
  // direction: +1 when steps come in increasing order (the forward pass), -1 when decreasing (the adjoint).
  explicit WarmStart(int direction) : direction_(direction) {}

  // Solutions of `size` entries; forgets the history.
  void resize(int size);
  void forget() { count_ = 0; }
  // When the last remembered solution is step n - direction's: the guess for step n into x, and true.
  // Otherwise false, x untouched.
  bool guess(int n, VecX& x) const;
  // Remembers x as step n's solution; the history restarts when n does not follow the last step.
  void remember(int n, const VecX& x);
  // The history a guess for step n needs, as one vector (empty when there is none), and back.
  void save(int n, VecX& context) const;
  void restore(int n, const VecX& context);

 private:
  int direction_;
  int size_ = 0, count_ = 0, last_ = 0;  // count_ solutions of consecutive steps, the newest of step last_
  VecX s_[3];                            // s_[0] the newest
};

}  // namespace kf
