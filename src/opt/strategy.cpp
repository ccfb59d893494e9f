#include "opt/strategy.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "core/error.h"
#include "opt/keyframe_weights.h"
#include "opt/restarts.h"
#include "opt/throw_fit.h"

namespace kf {

namespace {

// One run of the strategy: its setup, hooks and log, and what it has found so far.
struct Run {
  const Scene& scene;
  const StagePlan plan;
  const bool fixed_budgets, resuming;
  const bool from_controls;  // the first stage starts from controls read from a file (a resume without evaluations)
  bool scaled_first_step;
  const std::filesystem::path controls_file;
  const std::atomic<bool>* stop;
  const StrategyHooks& hooks;
  StrategyLog& log;
  std::uint64_t all_evaluations = 0;  // recorded on one tape over all stages
  TimeSpec z_time;                    // the time discretisation the controls in r.z were made for
  std::vector<double> weight_scales;  // the keyframe weights' scales every new stage's problem gets
  StrategyResult r;
};

// The stage's problem (its controls carried over from the previous stage's, or the initial guess) with its
// checkpointing and memory budget set; gives the memory line to print.
std::string set_up_stage(Run& run, const StageSpec& stage) {
  StrategyResult& r = run.r;
  Scene stage_scene = run.scene;  // a stage may optimise a coarser control parameterisation
  if (stage.controls) stage_scene.controls = *stage.controls;
  VecX& z = r.z;
  // The first frame of the previous stage's forces (a resumed run's controls are the scene's).
  const int z_from_frame = r.problem ? r.problem->controls().first_frame() : run.scene.controls.from_frame;
  VecX v0_before;  // the initial velocities the previous stage's kind gave, when the kind changes
  if (r.problem && r.problem->controls().forces())
    z = r.problem->controls().per_particle_forces(z);  // what remap_from takes (a lattice spread out)
  else if (r.problem && r.problem->controls().kind() != stage_scene.controls.kind)
    r.problem->controls().initial_velocity(z, v0_before);
  r.problem = std::make_unique<Problem>(stage_scene, r.time, *r.sys);
  Problem& problem = *r.problem;
  problem.set_weight_scales(run.weight_scales);
  r.tape.begin_stage({std::uint64_t(problem.size()), problem.controls().kind(), problem.controls().first_frame(),
                      r.time.substeps});
  r.tape.expect(std::uint64_t(problem.size()), run.all_evaluations);
  std::string memory_line;
  if (run.hooks.configure_problem)
    memory_line = run.hooks.configure_problem(
        problem, *r.sys, std::size_t(r.tape.bytes_for(std::uint64_t(problem.size()), run.all_evaluations)));
  if (z.size() == 0) z = problem.initial_guess();
  else if (v0_before.size()) z = problem.controls().from_initial_velocity(v0_before);
  else z = problem.controls().remap_from(z, run.z_time, z_from_frame);
  if (z.size() != problem.size())
    throw InputError(run.controls_file.string() + ": holds " + std::to_string(z.size()) +
                     " controls, the scene needs " + std::to_string(problem.size()));
  run.z_time = r.time;
  return memory_line;
}

// Controls read from controls.bin under which the simulation diverges (or the objective is not finite)
// are bad input: refused before the optimiser starts, not reported as a run that missed its keyframes.
void check_resumed_controls(const Run& run, Problem& problem, const VecX& z) {
  problem.evaluate(z, nullptr);
  if (!problem.last_diverged()) return;
  const int step = problem.rollout().diverged_at;
  std::ostringstream largest;
  largest << std::setprecision(3) << z.cwiseAbs().maxCoeff();
  const std::string why = problem.system().divergence_reason();
  throw InputError(run.controls_file.string() + ": " +
                   (step >= 0 ? "the simulation diverges at step " + std::to_string(step) +
                                    (why.empty() ? std::string() : " (" + why + ")")
                              : std::string("the objective is not finite")) +
                   " under these controls (largest magnitude " + largest.str() + "), so there is no run to resume "
                   "from them");
}

void say_stage(Run& run, int stage_id) {
  const Problem& problem = *run.r.problem;
  const TimeSpec& time = run.r.time;
  run.log.say(std::string(run.resuming ? "resuming " : "optimising ") + run.scene.name +
              (stage_id ? " stage " + std::to_string(stage_id) : "") + ": " + run.r.sys->describe() + ", " +
              std::to_string(time.steps()) + " steps (h = " + std::to_string(time.h()) + " s), " +
              std::to_string(problem.size()) + " control variables (" + problem.controls().kind_name() +
              (problem.controls().first_frame() > 0 ? " from frame " + std::to_string(problem.controls().first_frame())
                                                    : "") +
              ")");
}

void record_stage(Run& run, const OptimizeResult& res) {
  StrategyResult& r = run.r;
  r.z = res.z;
  StageOutcome st;
  st.kind = r.problem->controls().kind();
  st.substeps = r.time.substeps;
  st.evaluations = res.evaluations;
  st.objective_start = res.history.empty() ? res.phi : res.history.front().phi;
  st.objective_end = res.phi;
  st.reason = res.reason;
  st.status = res.status;
  r.stages.push_back(st);
  r.seconds += res.seconds;
  r.evaluations += res.evaluations;
  r.capped_trials += res.capped_trials;
  r.reason = res.reason;
  r.status = res.status;
  r.interrupted = res.interrupted;
}

// A cloth step the energy check splits is a jump in φ wherever the check flips between two trial points,
// and a line search stalls on it. Each stage simulates its start once and holds the step schedule it took;
// gives φ there.
double hold_schedule_at(StrategyResult& r, const VecX& z) {
  if (!r.hold_splits) return 0;
  r.sys->release_step_schedule();
  const double phi = r.problem->evaluate(z, nullptr);
  r.schedule = r.sys->step_schedule();
  r.sys->hold_step_schedule(r.schedule);
  return phi;
}

// Before a restart from `z` (φ = phi under the held schedule): holds the schedule z takes now, when φ is no
// worse under it (phi becomes that φ); else keeps the old one and says not to restart.
bool rehold_schedule(StrategyResult& r, const VecX& z, double& phi) {
  StepSchedule old = r.schedule;
  const double now = hold_schedule_at(r, z);
  if (now <= phi) {
    phi = now;
    return true;
  }
  r.schedule = std::move(old);
  r.sys->hold_step_schedule(r.schedule);
  return false;
}

// The search over rigid throws before a rigid first stage (opt/throw_search.h): every step is checked
// while the throws differ, then the best one's schedule is held. Deterministic, so a resume that replays
// the run's evaluations searches again and starts where the run did.
void search_throws_first(Run& run) {
  constexpr int kThrowCorrections = 3;  // four flights, a small share of the search
  StrategyResult& r = run.r;
  r.sys->release_step_schedule();
  const auto t0 = std::chrono::steady_clock::now();
  const ThrowSearch found = search_throws(*r.problem, run.plan.throw_search,
                                          refine_fitted_throw(*r.problem, run.scene, kThrowCorrections), run.stop);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::ostringstream os;
  os << std::setprecision(3) << "throw search: " << found.simulated << " rigid throws simulated (speeds within "
     << found.speed << " m/s, spins within " << found.spin << " rad/s of the scene's) in " << std::fixed
     << std::setprecision(2) << seconds << " s; " << std::scientific << std::setprecision(3);
  if (found.phi < found.start_phi) os << "the best has objective " << found.phi << ", the scene's throw " << found.start_phi;
  else os << "none beats the scene's throw (objective " << found.start_phi << ")";
  if (!found.fitted.empty()) {
    os << "; the throw fitted to the keyframes " << found.fitted.front();
    for (size_t k = 1; k < found.fitted.size(); ++k) os << (k == 1 ? ", corrected " : ", ") << found.fitted[k];
  }
  run.log.say(os.str());
  r.throw_search = found;
  r.throw_seconds = seconds;
  r.z = found.z;
  hold_schedule_at(r, r.z);
}

// optimizer.stop_when_reached, asked of the problem's last rollout. A checkpointed rollout keeps too few
// states to judge: the log says so once, and the run goes on by its other rules.
std::function<bool()> keyframes_reached(Run& run, Problem& problem) {
  if (!run.scene.optimizer.stop_when_reached || !run.hooks.keyframes_met) return {};
  return [&run, &problem, warned = false]() mutable {
    if (problem.rollout().every != 0) {
      if (!warned) run.log.say("stop_when_reached: not judged while the rollout is checkpointed");
      warned = true;
      return false;
    }
    return run.hooks.keyframes_met(problem);
  };
}

// Stage s of the plan: its system (the first is built already), problem and optimisation.
void run_stage(Run& run, const std::vector<StageSpec>& stages, size_t s) {
  StrategyResult& r = run.r;
  r.time.substeps = stages[s].substeps;
  if (s > 0) r.sys = run.hooks.make_system(r.time.h());
  const bool from_controls_file = run.resuming && s == 0 && r.z.size() > 0;
  const std::string memory_line = set_up_stage(run, stages[s]);
  // A stage at the last one's steps goes on with its schedule: under another, its best point may lie far off.
  if (r.hold_splits && r.schedule.steps() == r.time.steps()) r.sys->hold_step_schedule(r.schedule);
  else hold_schedule_at(r, r.z);
  Problem& problem = *r.problem;
  if (from_controls_file) check_resumed_controls(run, problem, r.z);
  if (s == 0 && run.plan.throw_search > 0 && !from_controls_file) search_throws_first(run);
  if (run.stop && run.stop->load()) {  // before the stage's first evaluation: no stage to record
    r.interrupted = true;
    r.reason = StopReason::kInterrupted;
    r.status = "interrupted";
    return;
  }
  const int stage_id = stages.size() > 1 ? int(s) + 1 : 0;
  say_stage(run, stage_id);
  if (problem.checkpoint_every() == 0 && !memory_line.empty()) run.log.say(memory_line);
  OptimizerSpec spec = run.scene.optimizer;
  spec.max_evaluations = stages[s].max_evaluations;
  if (spec.first_step < 0) spec.first_step = run.scaled_first_step ? problem.control_scale() : 0;
  RestartHooks hooks;
  const int substeps = r.time.substeps;
  const double seconds_before = r.seconds;
  hooks.on_eval = [&](const EvaluationRecord& e) { run.log.evaluation(stage_id, substeps, seconds_before, e); };
  hooks.say = [&](const std::string& line) { run.log.say(line); };
  if (r.hold_splits) hooks.before_restart = [&](const VecX& z, double& phi) { return rehold_schedule(r, z, phi); };
  hooks.reached = keyframes_reached(run, problem);
  run.log.stage_started(spec.max_evaluations);
  const OptimizeResult res =
      minimize_with_restarts(problem, spec, run.scene.optimizer.restarts, r.z, hooks, run.stop, r.tape);
  run.log.stage_finished();
  record_stage(run, res);
}

// Runs stages[first], stages[first + 1], ...: a stage that converged or stalled early leaves its unspent
// evaluations to the next (unless every stage has a fixed budget).
void run_stages(Run& run, std::vector<StageSpec>& stages, size_t first) {
  for (size_t s = first;
       s < stages.size() && !run.r.interrupted && run.r.reason != StopReason::kKeyframesReached; ++s) {
    const size_t recorded = run.r.stages.size();
    run_stage(run, stages, s);
    if (run.r.stages.size() == recorded) break;  // stopped before the stage's first evaluation
    if (s + 1 < stages.size() && !run.fixed_budgets)
      stages[s + 1].max_evaluations += std::max(0, stages[s].max_evaluations - run.r.stages.back().evaluations);
  }
}

// After a single stage of forces that ended early, stalled or converged, with evaluations left
// (StagePlan::windows_on_early_end): the windows from no force with what is left, appended to `stages`; the
// single stage's result is kept when the windows end no lower.
void windows_after_early_end(Run& run, std::vector<StageSpec>& stages) {
  StrategyResult& r = run.r;
  if (r.stages.empty()) return;
  const StageOutcome single = r.stages.back();
  const int left = stages[0].max_evaluations - single.evaluations;
  // A run resumed from its evaluations replays its stages, windows included; one continued from controls.bin
  // has only its last stage.
  if (!run.plan.windows_on_early_end || stages.size() != 1 || r.interrupted || run.from_controls || run.fixed_budgets ||
      !ended_early(single.reason) || left < std::max(10, stages[0].max_evaluations / 10))
    return;
  const VecX best = r.z;
  const StepSchedule best_schedule = r.schedule;
  std::vector<StageSpec> windows = window_stages(run.scene, left);
  std::ostringstream os;
  os << "the one stage ended (" << single.status << ") at objective " << std::scientific << std::setprecision(3)
     << single.objective_end << " with " << left
     << " evaluations left: windows grown back from the last keyframe, from no force";
  run.log.say(os.str());
  run.scaled_first_step = true;
  r.problem.reset();
  r.z = VecX();
  run.z_time = run.scene.time;
  stages.insert(stages.end(), windows.begin(), windows.end());
  run_stages(run, stages, 1);
  if (r.stages.back().objective_end < single.objective_end) return;
  run.log.say("the windows ended no lower: the one stage's result is kept");
  r.z = best;
  r.schedule = best_schedule;
  if (r.hold_splits) r.sys->hold_step_schedule(r.schedule);
}

// The keyframe terms of the problem's last evaluation at the scene's weights (infinite after a divergence).
double scene_keyframe_terms(const Problem& problem) {
  const auto& terms = problem.breakdown();
  const auto& scales = problem.weight_scales();
  if (terms.empty() || terms.back().first != "effort") return INFINITY;
  double sum = 0;
  for (size_t k = 0; k + 1 < terms.size(); ++k) sum += terms[k].second / (scales.empty() ? 1.0 : scales[k]);
  return sum;
}

// Keyframes are met, effort is minimised (opt/keyframe_weights.h): after a last stage that ended early with a
// keyframe outside its tolerance, stages with that keyframe's weight raised, from the best point, with the
// evaluations the plan has left; appended to `stages`.
void press_missed_keyframes(Run& run, std::vector<StageSpec>& stages) {
  StrategyResult& r = run.r;
  const KeyframeWeightRule rule;
  if (run.scene.optimizer.soft_keyframes || !run.hooks.keyframes_unmet || run.fixed_budgets) return;
  for (int round = 0; round < rule.rounds; ++round) {
    if (r.stages.empty() || !r.problem || r.interrupted || !ended_early(r.stages.back().reason)) return;
    Problem& problem = *r.problem;
    problem.evaluate(r.z, nullptr);  // every state kept: the judgement reads the frames
    if (problem.last_diverged()) return;
    const std::vector<bool> unmet = run.hooks.keyframes_unmet(problem);
    if (!any_unmet(unmet)) return;
    const int left = int(run.all_evaluations) - r.evaluations;
    if (left < rule.min_evaluations) return;
    const double before = scene_keyframe_terms(problem);
    std::vector<std::string> names;
    for (const auto& term : problem.breakdown()) names.push_back(term.first);
    run.weight_scales = raised_weight_scales(problem.weight_scales(), unmet, rule, round + 1);
    run.log.say(describe_raise(names, run.weight_scales, unmet) + " with " + std::to_string(left) + " evaluations");
    const VecX z_before = r.z;
    const StepSchedule schedule_before = r.schedule;
    stages.push_back(StageSpec{r.time.substeps, left, std::nullopt});
    ++r.weight_rounds;
    run_stages(run, stages, stages.size() - 1);
    if (r.interrupted) return;
    r.problem->evaluate(r.z, nullptr);
    const double after = scene_keyframe_terms(*r.problem);
    if (after < rule.keep_below * before) continue;
    std::ostringstream os;
    os << std::scientific << std::setprecision(3) << "the raised weights took the keyframe terms from " << before
       << " to " << after << ": the point before them is kept";
    run.log.say(os.str());
    r.z = z_before;
    r.schedule = schedule_before;
    if (r.hold_splits) r.sys->hold_step_schedule(r.schedule);
    return;
  }
}

}  // namespace

StrategyResult run_strategy(StrategySetup setup, const StrategyHooks& hooks, StrategyLog& log) {
  const Scene& scene = setup.scene;
  Run run{scene,           setup.plan,          setup.fixed_budgets,
          setup.resuming,  setup.start.size() > 0, setup.plan.scaled_first_step,
          setup.controls_file, setup.stop,        hooks,
          log};
  std::vector<StageSpec> stages = setup.plan.stages;
  for (const auto& st : stages) run.all_evaluations += std::uint64_t(std::max(st.max_evaluations, 1));
  run.z_time = setup.start.size() ? setup.start_time : scene.time;
  StrategyResult& r = run.r;
  r.tape = std::move(setup.tape);
  r.z = std::move(setup.start);
  r.time = scene.time;
  r.time.substeps = stages[0].substeps;
  r.sys = std::move(setup.system);
  r.hold_splits = scene.cloth && scene.optimizer.split_schedule == SplitSchedule::kHeld;
  run_stages(run, stages, 0);
  windows_after_early_end(run, stages);
  press_missed_keyframes(run, stages);
  r.weight_scales = run.weight_scales;
  if (r.problem) r.problem->set_weight_scales({});
  r.planned_stages = int(stages.size());
  return std::move(run.r);
}

}  // namespace kf
