#pragma once
// One stage's optimisation: L-BFGS, then fresh starts from the best point after a stalled line search (an
// approximate gradient, or a held split pattern gone stale, stalls the line search long before the
// objective stops falling).
#include <atomic>
#include <functional>
#include <string>

#include "opt/evaluation_tape.h"
#include "opt/optimizer.h"
#include "opt/problem.h"

namespace kf {

struct RestartHooks {
  // Each evaluation, numbered and timed over all the starts of the stage.
  std::function<void(const EvaluationRecord&)> on_eval;
  // A line for people ("restart 1 from objective ...").
  std::function<void(const std::string&)> say;
  // Before a restart from z with objective phi: false keeps the stage's result and restarts no more; it may
  // lower phi (the objective under a schedule held anew: sim/system.h).
  std::function<bool(const VecX& z, double& phi)> before_restart;
  // The stop rule (minimize's `reached`).
  std::function<bool()> reached;
};

// L-BFGS from z within spec.max_evaluations, then up to `restarts` fresh starts from the best point after
// a stalled line search, with what is left of the budget, while they make progress.
OptimizeResult minimize_with_restarts(Problem& problem, OptimizerSpec spec, int restarts, const VecX& z,
                                      const RestartHooks& hooks, const std::atomic<bool>* stop, EvaluationTape& tape);

}  // namespace kf
