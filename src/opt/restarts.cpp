#include "opt/restarts.h"

namespace kf {

OptimizeResult minimize_with_restarts(Problem& problem, OptimizerSpec spec, int restarts, const VecX& z,
                                      const RestartHooks& hooks, const std::atomic<bool>* stop, EvaluationTape& tape) {
  const int budget = spec.max_evaluations;
  int used = 0;       // evaluations of the earlier starts of this stage
  double before = 0;  // and their seconds
  const auto on_eval = [&](const EvaluationRecord& r0) {
    if (!hooks.on_eval) return;
    EvaluationRecord r = r0;
    r.evaluation += used;
    r.seconds += before;
    hooks.on_eval(r);
  };
  OptimizeResult res = minimize(problem, spec, z, on_eval, stop, &tape, hooks.reached);
  for (int k = 0; k < restarts && !res.interrupted; ++k) {
    const int left = budget - int(res.history.size());
    if (res.reason != StopReason::kLineSearchStalled || left < 3) break;
    if (hooks.say)
      hooks.say("restart " + std::to_string(k + 1) + " from objective " + std::to_string(res.phi) + ", " +
                std::to_string(left) + " evaluations left");
    spec.max_evaluations = left;
    before = res.seconds;
    used = int(res.history.size());
    const VecX best = res.z;
    double best_phi = res.phi;
    if (hooks.before_restart && !hooks.before_restart(best, best_phi)) break;
    OptimizeResult more = minimize(problem, spec, best, on_eval, stop, &tape, hooks.reached);
    more.seconds += before;
    more.evaluations += res.evaluations;
    more.history.insert(more.history.begin(), res.history.begin(), res.history.end());
    const bool progress_made = more.phi < best_phi * (1 - 1e-6);
    if (!(more.phi < best_phi)) {  // no progress: keep the earlier best point
      more.z = best;
      more.phi = best_phi;
    }
    res = std::move(more);
    if (!progress_made) break;  // the gradient is no descent direction here: restarting again will not help
  }
  return res;
}

}  // namespace kf
