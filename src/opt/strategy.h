#pragma once
// The optimisation strategy: plan and execution of a run's stages (opt/windows.h plans them). It carries
// the controls from stage to stage, passes a stage's unspent evaluations on to the next, restarts a stage
// after a stalled line search (opt/restarts.h), searches rigid throws before a rigid first stage
// (opt/throw_search.h), optimises again in windows after a single stage that ended early, holds each
// stage's step schedule (sim/system.h: the cloth's split pattern) and stops when the keyframes are reached.
// It knows nothing of run directories or reports: what it builds and says goes through StrategyHooks and
// StrategyLog, and what it found comes back typed (StrategyResult).
#include <atomic>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "opt/evaluation_tape.h"
#include "opt/optimizer.h"
#include "opt/problem.h"
#include "opt/throw_search.h"
#include "opt/uniform_push.h"
#include "opt/windows.h"
#include "scene/scene.h"
#include "sim/system.h"

namespace kf {

// What a run's owner hears from the strategy.
class StrategyLog {
 public:
  virtual ~StrategyLog() = default;
  virtual void say(const std::string& line) = 0;
  // One evaluation of stage `stage_id` (0: the only stage), run at `substeps`, after `seconds_before` seconds
  // of earlier stages.
  virtual void evaluation(int stage_id, int substeps, double seconds_before, const EvaluationRecord& r) = 0;
  // A stage's optimisation begins with at most `max_evaluations` evaluations, and ends.
  virtual void stage_started(int /*max_evaluations*/) {}
  virtual void stage_finished() {}
};

// What the strategy asks of the one who runs it.
struct StrategyHooks {
  // The system a later stage simulates, at step length h (the first stage's is given).
  std::function<std::unique_ptr<System>(double h)> make_system;
  // Sets a stage's fresh problem's checkpointing and memory budget, knowing the evaluation tape may hold
  // `tape_bytes`; gives the line that states it (said when the problem keeps every step). Empty: neither.
  std::function<std::string(Problem&, System&, std::size_t tape_bytes)> configure_problem;
  // optimizer.stop_when_reached: whether the problem's last rollout (every step kept) meets every
  // keyframe's tolerance. Empty: the run never stops for it.
  std::function<bool(Problem&)> keyframes_met;
  // For each of the scene's objectives, whether the problem's last rollout (every step kept) leaves it outside
  // its tolerance: the keyframes whose weights a run that ended early raises (opt/keyframe_weights.h).
  // Empty: weights are never raised.
  std::function<std::vector<bool>(Problem&)> keyframes_unmet;
};

// One stage as it ended.
struct StageOutcome {
  ControlKind kind = ControlKind::kPerStep;  // its controls'
  int substeps = 0, evaluations = 0;
  double objective_start = 0, objective_end = 0;
  StopReason reason = StopReason::kOther;
  std::string status;  // the reason for people
};

struct StrategySetup {
  const Scene& scene;
  StagePlan plan;
  // --max-evaluations: every stage has its own budget, passes nothing on, and no windows follow an early end.
  bool fixed_budgets = false;
  bool resuming = false;
  // Controls to start the first stage from (a resumed run's controls.bin) at `start_time`; empty: the
  // initial guess (or the throw search's best).
  VecX start;
  TimeSpec start_time;
  StepSchedule start_schedule;          // the step schedule `start` was judged under (schedule.bin); empty: chosen anew
  std::filesystem::path controls_file;  // named in messages about the controls
  std::unique_ptr<System> system;       // the first stage's
  EvaluationTape tape;                  // what it replays (a resume), and where every evaluation is recorded
  const std::atomic<bool>* stop = nullptr;  // set (by a signal) to end the run with the best point so far
};

struct StrategyResult {
  EvaluationTape tape;  // every evaluation, for a resume that continues exactly where this run stopped
  VecX z;               // the best controls of the last stage
  TimeSpec time;        // its time discretisation
  std::unique_ptr<System> sys;
  std::unique_ptr<Problem> problem;
  StopReason reason = StopReason::kOther;  // why the last stage stopped
  std::string status;                      // the same for people
  bool interrupted = false;
  int evaluations = 0;
  int capped_trials = 0;  // trials refused unsimulated after an unstable one (OptimizeResult::capped_trials)
  double seconds = 0;
  std::vector<StageOutcome> stages;
  int planned_stages = 0;  // the plan's, with the windows after an early end
  int scaled_budget = 0;   // StagePlan::scaled_budget
  bool hold_splits = false;  // optimizer.split_schedule "held", on cloth
  StepSchedule schedule;     // the step schedule the last stage held
  // Each keyframe's weight over the scene's in the last stage (empty: the scene's); the result's problem is
  // left at the scene's weights, so what a report evaluates is the scene's objective.
  std::vector<double> weight_scales;
  int weight_rounds = 0;  // stages run with raised keyframe weights
  // Non-empty when the result left a keyframe worse than uncontrolled and the run ended at an earlier stage's
  // end or at no control instead (opt/uncontrolled_floor.h): why, for people.
  std::string fallback;
  std::optional<ThrowSearch> throw_search;  // what the search over rigid throws found
  double throw_seconds = 0;
  std::optional<UniformPush> uniform_push;  // the push fitted before a sheet's first stage of forces
  // Sets the system's schedule as the result's optimisation saw it (after simulating anything else).
  void hold_result_schedule() {
    if (hold_splits) sys->hold_step_schedule(schedule);
  }
};

StrategyResult run_strategy(StrategySetup setup, const StrategyHooks& hooks, StrategyLog& log);

}  // namespace kf
