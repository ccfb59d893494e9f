#pragma once
// L-BFGS (NLopt LD_LBFGS) on a Problem, keeping the best point and a record of every evaluation.
#include <atomic>
#include <functional>
#include <string>
#include <vector>

#include "opt/evaluation_tape.h"
#include "opt/problem.h"
#include "scene/objective_spec.h"

namespace kf {

struct EvaluationRecord {
  int evaluation = 0;  // 1-based count of φ evaluations (each one forward + one adjoint pass)
  double phi = 0;
  double grad_norm = 0;
  double seconds = 0;  // since the start of the optimisation
  bool diverged = false;
  bool unstable = false;  // diverged because the system refused a step as unstable (System::divergence_reason)
  std::vector<std::pair<std::string, double>> terms;
};

// Why an optimisation (or a strategy's stage) stopped. Decisions read this; `status` texts are for people.
enum class StopReason {
  kConverged,          // NLopt's success, ftol_rel, step tolerance or round-off
  kStopValue,          // the objective fell below a stop value
  kLineSearchStalled,  // L-BFGS's line search made no progress
  kEvaluationLimit,
  kTimeLimit,
  kKeyframesReached,   // the stop rule said the best point meets every keyframe
  kInterrupted,        // a signal asked the run to stop
  kNotOptimised,       // no optimisation was asked for (no evaluations, or no controls)
  kOther,              // another NLopt result (its code is in the status text)
};
// A budget ran out (evaluations or time).
inline bool budget_spent(StopReason r) { return r == StopReason::kEvaluationLimit || r == StopReason::kTimeLimit; }
// The optimisation ended on its own before its budget: it converged or its line search stalled.
inline bool ended_early(StopReason r) { return r == StopReason::kConverged || r == StopReason::kLineSearchStalled; }

struct OptimizeResult {
  VecX z;               // best point found
  double phi = 0;       // φ at z
  int evaluations = 0;
  double seconds = 0;
  StopReason reason = StopReason::kOther;  // why it stopped
  std::string status;   // the same for people (NLopt's words)
  bool interrupted = false;
  int capped_trials = 0;  // trials refused unsimulated as farther than the reach left by an unstable one
  bool reached = false;   // stopped because `reached` said the best point meets the keyframes
  std::vector<EvaluationRecord> history;
};

// Minimises φ from z0 within spec.max_evaluations (a hard limit). `on_eval` sees each evaluation as it
// happens; setting *stop makes the next evaluation end the optimisation with the best point so far (used for
// SIGINT/SIGTERM). With a `tape`, every evaluation is recorded on it, and evaluations it replays (an
// interrupted run resumed) are taken from it instead of computed. `reached`, when given, is asked after each
// simulated evaluation that improves on the best point (the problem's rollout is then that point's); true
// ends the optimisation there, with StopReason::kKeyframesReached.
OptimizeResult minimize(Problem& problem, const OptimizerSpec& spec, const VecX& z0,
                        const std::function<void(const EvaluationRecord&)>& on_eval = {},
                        const std::atomic<bool>* stop = nullptr, EvaluationTape* tape = nullptr,
                        const std::function<bool()>& reached = {});

inline constexpr const char* kKeyframesReached = "keyframes reached";

}  // namespace kf
