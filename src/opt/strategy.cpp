#include "opt/strategy.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "core/error.h"
#include "opt/friction_continuation.h"
#include "opt/keyframe_projection.h"
#include "opt/keyframe_weights.h"
#include "opt/near_miss_projection.h"
#include "opt/restarts.h"
#include "opt/term_breakdown.h"
#include "opt/throw_fit.h"
#include "opt/uniform_push.h"
#include "opt/uncontrolled_floor.h"
#include "sim/make_system.h"

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
  std::vector<int> judged_until;      // per stage, the frame its keyframes count up to (opt/windows.h)
  std::vector<double> friction_scales;  // per stage, on the scene's friction (StagePlan::friction_scales)
  std::vector<VecX> stage_ends;       // each stage's best controls as the scene's own (opt/uncontrolled_floor.h)
  int projected = 0;                  // a large sheet's evaluations spent in Gauss-Newton's passes (run_stage)
  StrategyResult r;
};

// Forces before `first_step` that `prev` applies under z (its held ones and its controls'): what a window later
// in time holds (opt/windows.h). Empty when they are all zero.
std::vector<VecX> forces_before(const Problem& prev, const VecX& z, int first_step) {
  std::vector<VecX> held(size_t(std::max(0, first_step)));
  bool any = false;
  for (size_t n = 0; n < held.size(); ++n) {
    prev.force_at(z, int(n), held[n]);
    any = any || held[n].squaredNorm() > 0;
  }
  if (!any) held.clear();
  return held;
}

// The forces `prev` applies under z from `next`'s first step on, as next's per-particle blocks (a frame's or a
// step's force): what remap_from takes, with the held forces a window grown back over them takes in.
VecX forces_as_blocks(const Problem& prev, const VecX& z, const Controls& next) {
  const int steps = prev.time().steps();
  const int stride = next.timing() == ControlTiming::kPerFrame ? prev.time().substeps : 1;
  std::vector<VecX> blocks;
  VecX u;
  for (int n = next.first_step(); n < steps; n += stride) {
    prev.force_at(z, n, u);
    blocks.push_back(u);
  }
  const long size = blocks.empty() ? 0 : long(blocks.size()) * blocks.front().size();
  VecX out(size);
  for (size_t b = 0; b < blocks.size(); ++b) out.segment(long(b) * blocks[b].size(), blocks[b].size()) = blocks[b];
  return out;
}

// z of the run's current problem as the scene's own controls (its held forces included); empty when they cannot
// be written so (initial velocities, another timing or step length).
VecX as_scene_controls(const Run& run, const VecX& z) {
  const StrategyResult& r = run.r;
  const Problem& p = *r.problem;
  if (!p.controls().forces() || r.time.substeps != run.scene.time.substeps) return {};
  Problem scene_problem(run.scene, r.time, *r.sys);
  const Controls& c = scene_problem.controls();
  if (!c.forces() || c.timing() != p.controls().timing()) return {};
  return c.remap_from(forces_as_blocks(p, z, c), r.time, c.first_frame());
}

// The keyframe weight scales of a stage judged on keyframes up to frame `until` (opt/windows.h): later ones 0.
std::vector<double> stage_scales(const Scene& scene, const std::vector<double>& scales, int until) {
  if (until == kAllKeyframes) return scales;
  std::vector<double> out(scene.objectives.size(), 1.0);
  for (size_t k = 0; k < out.size(); ++k) {
    if (k < scales.size()) out[k] = scales[k];
    if (scene.objectives[k].frame > until) out[k] = 0.0;
  }
  return out;
}

// The stage's problem (its controls carried over from the previous stage's, or the initial guess) with its
// checkpointing and memory budget set; gives the memory line to print. A window later in time than the
// previous stage's holds the forces before it; one grown back over held forces starts from them.
std::string set_up_stage(Run& run, const StageSpec& stage, int until) {
  StrategyResult& r = run.r;
  Scene stage_scene = run.scene;  // a stage may optimise a coarser control parameterisation
  if (stage.controls) stage_scene.controls = *stage.controls;
  VecX& z = r.z;
  std::unique_ptr<Problem> prev = std::move(r.problem);  // its system may be gone: only its controls are read
  r.problem = std::make_unique<Problem>(stage_scene, r.time, *r.sys);
  Problem& problem = *r.problem;
  const bool carry_forces = prev && prev->controls().forces() && problem.controls().forces() &&
                            prev->time().substeps == r.time.substeps && z.size() == prev->size();
  bool composed = false;
  if (carry_forces) {
    problem.hold_forces(forces_before(*prev, z, problem.controls().first_step()));
    if (!prev->held_forces().empty() && problem.controls().first_step() < prev->controls().first_step() &&
        prev->controls().timing() == problem.controls().timing() && !r.sys->planar()) {
      z = problem.controls().remap_from(forces_as_blocks(*prev, z, problem.controls()), r.time,
                                        problem.controls().first_frame());
      composed = true;
    }
  }
  // The first frame of the previous stage's forces (a resumed run's controls are the scene's).
  const int z_from_frame = prev ? prev->controls().first_frame() : run.scene.controls.from_frame;
  VecX v0_before;  // the initial velocities the previous stage's kind gave, when the kind changes
  if (prev && !composed) {
    if (prev->controls().forces()) z = prev->controls().per_particle_forces(z);  // what remap_from takes
    else if (prev->controls().kind() != stage_scene.controls.kind) prev->controls().initial_velocity(z, v0_before);
  }
  prev.reset();
  problem.set_weight_scales(stage_scales(run.scene, run.weight_scales, until));
  r.tape.begin_stage({std::uint64_t(problem.size()), problem.controls().kind(), problem.controls().first_frame(),
                      r.time.substeps});
  r.tape.expect(std::uint64_t(problem.size()), run.all_evaluations);
  std::string memory_line;
  if (run.hooks.configure_problem)
    memory_line = run.hooks.configure_problem(
        problem, *r.sys, std::size_t(r.tape.bytes_for(std::uint64_t(problem.size()), run.all_evaluations)));
  if (z.size() == 0) z = problem.initial_guess();
  else if (v0_before.size()) z = problem.controls().from_initial_velocity(v0_before);
  else if (!composed) z = problem.controls().remap_from(z, run.z_time, z_from_frame);
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
  StrategyResult& r = run.r;
  r.sys->release_step_schedule();
  const auto t0 = std::chrono::steady_clock::now();
  const ThrowSearch found = search_and_fit_throws(*r.problem, run.scene, run.plan.throw_search,
                                                  2 * run.scene.optimizer.max_evaluations, run.stop);
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
  if (found.rigid) os << "; " << describe(*found.rigid);
  run.log.say(os.str());
  r.throw_search = found;
  r.throw_seconds = seconds;
  r.z = found.z;
  hold_schedule_at(r, r.z);
}

// Before a thrown sheet's per-particle stage, when the stages before left a keyframe unmet: Gauss–Newton onto
// the unmet keyframes, then onto all (opt/keyframe_projection.h), with at most the stage's evaluations in
// simulations and adjoint passes; the stage starts from its result when that brings the worst keyframe nearer.
// Returns the evaluations its passes were worth (a simulation and an adjoint pass each).
int project_before_stage(Run& run, const StageSpec& stage) {
  StrategyResult& r = run.r;
  Problem& problem = *r.problem;
  if (!run.hooks.keyframes_unmet) return 0;
  problem.evaluate(r.z, nullptr);
  if (problem.last_diverged()) return 0;
  const std::vector<bool> unmet = run.hooks.keyframes_unmet(problem);
  if (!any_unmet(unmet)) return 0;
  ProjectionOptions o;
  o.max_passes = stage.max_evaluations;
  o.sketch = true;  // a keyframe on many particles costs a Jacobian of its moments, not three rows a particle
  o.stop = run.stop;
  const auto t0 = std::chrono::steady_clock::now();
  const KeyframeProjection p = project_unmet_then_all(problem, run.scene, r.z, unmet, o);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (p.stop == ProjectionStop::kNotApplicable) return 0;
  std::ostringstream os;
  os << describe(p) << " in " << std::fixed << std::setprecision(2) << seconds << " s";
  run.log.say(os.str());
  if (p.improved()) r.z = p.z;
  return (p.simulations + p.adjoint_passes + 1) / 2;
}

// optimizer.stop_when_reached, asked of the problem's last rollout. A checkpointed rollout keeps too few
// states to judge: the log says so once, and the run goes on by its other rules.
// A stage judged on the keyframes up to frame `until` ends when those are met.
std::function<bool()> keyframes_reached(Run& run, Problem& problem, int until) {
  if (!run.scene.optimizer.stop_when_reached || !run.hooks.keyframes_met) return {};
  if (until != kAllKeyframes && !run.hooks.keyframes_unmet) return {};
  return [&run, &problem, until, warned = false]() mutable {
    if (problem.rollout().every != 0) {
      if (!warned) run.log.say("stop_when_reached: not judged while the rollout is checkpointed");
      warned = true;
      return false;
    }
    if (until == kAllKeyframes) return run.hooks.keyframes_met(problem);
    const std::vector<bool> unmet = run.hooks.keyframes_unmet(problem);
    for (size_t k = 0; k < unmet.size() && k < run.scene.objectives.size(); ++k)
      if (unmet[k] && run.scene.objectives[k].frame <= until) return false;
    return true;
  };
}

int judged_until(const Run& run, size_t s) {
  return s < run.judged_until.size() ? run.judged_until[s] : kAllKeyframes;
}

double friction_scale(const Run& run, size_t s) {
  return s < run.friction_scales.size() ? run.friction_scales[s] : 1.0;
}

// Stage s's system at step length h: the hooks' at the scene's friction, else the scene's with it eased.
std::unique_ptr<System> stage_system(const Run& run, size_t s, double h) {
  const double scale = friction_scale(run, s);
  return scale == 1.0 ? run.hooks.make_system(h) : make_system(with_friction_scaled(run.scene, scale), h);
}

// Stage s of the plan: its system (the first is built already), problem and optimisation.
void run_stage(Run& run, const std::vector<StageSpec>& stages, size_t s) {
  StrategyResult& r = run.r;
  r.time.substeps = stages[s].substeps;
  const bool friction_changed = s > 0 && friction_scale(run, s) != friction_scale(run, s - 1);
  if (s > 0 || friction_scale(run, s) != 1.0) r.sys = stage_system(run, s, r.time.h());
  const bool from_controls_file = run.resuming && s == 0 && r.z.size() > 0;
  const std::string memory_line = set_up_stage(run, stages[s], judged_until(run, s));
  // A stage at the last one's steps goes on with its schedule: under another, its best point may lie far off.
  if (r.hold_splits && r.schedule.steps() == r.time.steps() && !friction_changed) r.sys->hold_step_schedule(r.schedule);
  else hold_schedule_at(r, r.z);
  Problem& problem = *r.problem;
  if (from_controls_file) check_resumed_controls(run, problem, r.z);
  if (s == 0 && run.plan.throw_search > 0 && !from_controls_file) search_throws_first(run);
  int projected = 0;  // the evaluations Gauss-Newton's passes were worth
  if (s > 0 && run.plan.throw_search > 0 && problem.controls().kind() == ControlKind::kInitialVelocity &&
      stages[s - 1].controls && !(run.stop && run.stop->load()))  // the first per-particle stage only
    projected = project_before_stage(run, stages[s]);
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
  // A large sheet's plan (opt/windows.cpp) spends its stage's evaluations once: Gauss-Newton's passes count.
  if (projected > 0 && run.scene.cloth && large_flight_share(run.scene.cloth->particles(), run.scene.time.steps()) < 1) {
    spec.max_evaluations = std::max(1, spec.max_evaluations - projected);
    run.projected += projected;
  }
  if (spec.first_step < 0) spec.first_step = run.scaled_first_step ? problem.control_scale() : 0;
  RestartHooks hooks;
  const int substeps = r.time.substeps;
  const double seconds_before = r.seconds;
  hooks.on_eval = [&](const EvaluationRecord& e) { run.log.evaluation(stage_id, substeps, seconds_before, e); };
  hooks.say = [&](const std::string& line) { run.log.say(line); };
  if (r.hold_splits) hooks.before_restart = [&](const VecX& z, double& phi) { return rehold_schedule(r, z, phi); };
  hooks.reached = keyframes_reached(run, problem, judged_until(run, s));
  run.log.stage_started(spec.max_evaluations);
  const OptimizeResult res =
      minimize_with_restarts(problem, spec, run.scene.optimizer.restarts, r.z, hooks, run.stop, r.tape);
  run.log.stage_finished();
  record_stage(run, res);
  run.stage_ends.push_back(as_scene_controls(run, res.z));
}

// Runs stages[first], stages[first + 1], ...: a stage that converged or stalled early leaves its unspent
// evaluations to the next (unless every stage has a fixed budget). A window that met the keyframes it is
// judged on skips the longer windows of the same keyframes.
void run_stages(Run& run, std::vector<StageSpec>& stages, size_t first) {
  for (size_t s = first;
       s < stages.size() && !run.r.interrupted && run.r.reason != StopReason::kKeyframesReached; ++s) {
    const size_t recorded = run.r.stages.size();
    run_stage(run, stages, s);
    if (run.r.stages.size() == recorded) break;  // stopped before the stage's first evaluation
    const int until = judged_until(run, s);
    size_t next = s + 1;
    if (until != kAllKeyframes && run.r.reason == StopReason::kKeyframesReached) {
      while (next + 1 < stages.size() && judged_until(run, next) == until) {
        if (!run.fixed_budgets) stages[next + 1].max_evaluations += stages[next].max_evaluations;
        ++next;
      }
      run.r.reason = StopReason::kConverged;  // of the run: its later keyframes are still to be met
      run.log.say("the keyframes up to frame " + std::to_string(until) + " are met: on to the next keyframe");
    } else if (friction_scale(run, s) != 1.0 && run.r.reason == StopReason::kKeyframesReached) {
      while (next < stages.size() && friction_scale(run, next) != 1.0) {
        if (!run.fixed_budgets && next + 1 < stages.size())
          stages[next + 1].max_evaluations += stages[next].max_evaluations;
        ++next;
      }
      run.r.reason = StopReason::kConverged;  // at eased friction: the scene's is still to come
      run.log.say("the keyframes are met with friction eased: on to the scene's friction");
    }
    if (next < stages.size() && !run.fixed_budgets)
      stages[next].max_evaluations += std::max(0, stages[s].max_evaluations - run.r.stages.back().evaluations);
    s = next - 1;
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
  std::vector<int> until;
  std::vector<StageSpec> windows = window_stages(run.scene, left, &until);
  run.judged_until.resize(stages.size(), kAllKeyframes);
  run.judged_until.insert(run.judged_until.end(), until.begin(), until.end());
  std::ostringstream os;
  os << "the one stage ended (" << single.status << ") at objective " << std::scientific << std::setprecision(3)
     << single.objective_end << " with " << left
     << " evaluations left: windows from no force";
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
  if (!last_effort(problem)) return INFINITY;
  double sum = 0;
  for (size_t k = 0; k + 1 < terms.size(); ++k)
    if (scales.empty() || scales[k] > 0) sum += terms[k].second / (scales.empty() ? 1.0 : scales[k]);
  return sum;
}

// Before the first stage of a sheet's forces: the uniform push that best places the keyframes
// (opt/uniform_push.h), fitted under the scene's controls and carried into the first stage (forces before a
// window held, those in it its start) when it pays. A push past half the scene's gravity is no tilt of it (the
// fit pressing the whole sheet where the keyframes ask for a fold, a swing or a lift: napkin-fold 7.2 m/s²,
// cape-swing 15.2, a start the windows never left): a fit whose step would leave that ball ends there and is
// not kept. Nor is one that has not halved the keyframes' cost four steps in or at its end
// (tests/results/reachable/README.md, "The uniform push as a default"). A kept push's flights count as half an
// evaluation each (a simulation without the adjoint pass), taken from the last stage's budget: the first window
// keeps its share (napkin-fold's meets its keyframes at 118 of 150). A push not kept leaves the run as without
// it, budgets included; the log and the report (push_flights) say what it flew.
void push_uniformly_first(Run& run, std::vector<StageSpec>& stages) {
  constexpr int kFlights = 100;  // fourteen Jacobians and steps at most: a sixth of a default run's evaluations
  StrategyResult& r = run.r;
  if (!run.plan.uniform_push || !run.scene.cloth || run.from_controls || run.fixed_budgets || r.z.size() ||
      (run.stop && run.stop->load()))
    return;
  auto problem = std::make_unique<Problem>(run.scene, r.time, *r.sys);
  if (!problem->controls().forces()) return;
  // A large sheet's push flies no more than kFlights flights of kLargeFlight particle-steps would cost
  // (drop-collider-1, 784 particles over 38 steps: 40 flights, not 77 in 47 s).
  const double share = large_flight_share(problem->system().particles(), r.time.steps());
  const int flights = std::max(8, int(kFlights * share));
  FewFitOptions o = uniform_push_options(run.scene, std::min(flights, stages[0].max_evaluations));
  o.stop = run.stop;
  const auto t0 = std::chrono::steady_clock::now();
  UniformPush push = fit_uniform_push(*problem, run.scene, o);
  problem->evaluate(problem->initial_guess(), nullptr);
  const double before = scene_keyframe_terms(*problem);
  double after = INFINITY;
  if (push.z.size()) {
    problem->evaluate(push.z, nullptr);
    after = scene_keyframe_terms(*problem);
  }
  push.simulated += push.z.size() ? 2 : 1;
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const bool paid = push.stop != FitStop::kBounded && push.stop != FitStop::kNotPaying;
  const bool keep = paid && after < before;
  const int worth = keep ? (push.simulated + 1) / 2 : 0;
  if (keep) {
    stages.back().max_evaluations = std::max(1, stages.back().max_evaluations - worth);
    run.projected += worth;
  }
  std::ostringstream os;
  os << describe(push) << " in " << std::fixed << std::setprecision(2) << seconds << " s (charged " << worth
     << " evaluations); " << std::scientific << std::setprecision(3) << "keyframe terms " << before << " with none, "
     << after << " with it: " << (keep ? "the first stage starts from it" : "not kept");
  if (!paid) os << " (" << fit_stop_name(push.stop) << ")";
  run.log.say(os.str());
  r.uniform_push = push;
  if (!keep) return;
  r.z = push.z;
  r.problem = std::move(problem);
  run.z_time = r.time;
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
    const int left = int(run.all_evaluations) - r.evaluations - run.projected;
    if (left < rule.min_evaluations) return;
    const double before = scene_keyframe_terms(problem);
    std::vector<std::string> names;
    for (const auto& term : problem.breakdown()) names.push_back(term.first);
    run.weight_scales = raised_weight_scales(run.weight_scales, unmet, rule, round + 1);
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

// A run that ended with a keyframe unmet but near: Gauss–Newton onto the keyframes from its best point
// (opt/near_miss_projection.h), kept when it leaves no more keyframes unmet and the worst nearer. A run that met
// its keyframes is not touched.
void project_near_miss_at_end(Run& run) {
  StrategyResult& r = run.r;
  if (run.scene.optimizer.soft_keyframes || !run.hooks.keyframes_unmet || !r.problem || r.interrupted ||
      r.stages.empty() || run.from_controls || r.reason == StopReason::kKeyframesReached || (run.stop && run.stop->load()))
    return;
  const NearMissRule rule;
  const int passes = near_miss_passes(rule, int(run.all_evaluations) - r.evaluations, run.scene.optimizer.max_evaluations);
  if (passes < 2) return;  // the run spent its budget: not even judged again
  Problem& problem = *r.problem;
  const std::vector<double> stage_weights = problem.weight_scales();
  problem.set_weight_scales(run.weight_scales);
  const auto unmet_at = [&](const VecX& z, std::vector<bool>& unmet) {
    problem.evaluate(z, nullptr);
    if (problem.last_diverged()) return -1;
    unmet = run.hooks.keyframes_unmet(problem);
    return int(std::count(unmet.begin(), unmet.end(), true));
  };
  std::vector<bool> unmet;
  const int before = unmet_at(r.z, unmet);
  const double worst = before > 0 ? near_miss_worst(problem, run.scene) : 0;
  if (before > 0 && worst > rule.near_limit) {
    std::ostringstream os;
    os << std::setprecision(3) << "near miss: not projected (the worst keyframe " << worst << " tolerances off, over "
       << rule.near_limit << ")";
    run.log.say(os.str());
  } else if (before > 0) {
    const auto t0 = std::chrono::steady_clock::now();
    const KeyframeProjection p = project_near_miss(problem, run.scene, r.z, unmet, passes, rule, run.stop);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (p.stop != ProjectionStop::kNotApplicable) {
      std::vector<bool> after_unmet;
      const int after = p.improved() ? unmet_at(p.z, after_unmet) : -1;
      const bool keep = after >= 0 && after <= before;
      std::ostringstream os;
      os << "near miss: " << describe(p) << " in " << std::fixed << std::setprecision(2) << seconds << " s; "
         << (keep ? "kept" : "not kept") << " (" << before << " keyframe" << (before == 1 ? "" : "s") << " unmet before, "
         << (after < 0 ? std::string("not judged") : std::to_string(after)) << " after)";
      run.log.say(os.str());
      if (keep) r.z = p.z;
    }
  }
  problem.set_weight_scales(stage_weights);
}

// A run that ended in a window with forces held before it (interrupted, or its last stages skipped) gives
// its result in the scene's own controls, the held forces included: what controls.bin, a resume and the
// report read.
void release_held_forces(Run& run) {
  StrategyResult& r = run.r;
  if (!r.problem || r.problem->held_forces().empty()) return;
  auto scene_problem = std::make_unique<Problem>(run.scene, r.time, *r.sys);
  if (scene_problem->controls().timing() != r.problem->controls().timing()) return;
  r.z = scene_problem->controls().remap_from(forces_as_blocks(*r.problem, r.z, scene_problem->controls()), r.time,
                                             scene_problem->controls().first_frame());
  scene_problem->set_checkpoint_every(r.problem->checkpoint_every());
  scene_problem->set_memory_budget(r.problem->memory_budget());
  r.problem = std::move(scene_problem);
}

// A result that leaves a keyframe farther off than no control does falls back to the best stage end, or to no
// control, that does not (opt/uncontrolled_floor.h). Judged at the scene's weights in the scene's controls.
void keep_no_worse_than_uncontrolled(Run& run) {
  StrategyResult& r = run.r;
  if (!run.hooks.keyframes_unmet || !r.problem || r.interrupted || r.stages.empty() || run.from_controls) return;
  Problem& problem = *r.problem;
  if (!problem.held_forces().empty() || problem.controls().kind() != run.scene.controls.kind ||
      problem.controls().first_frame() != run.scene.controls.from_frame)
    return;
  std::vector<VecX> candidates{r.z};
  for (const VecX& z : run.stage_ends)
    if (z.size() == r.z.size()) candidates.push_back(z);
  // The result under the schedule its stage held, the others under their own (a cloth step's split pattern).
  const auto before = [&r](size_t c) {
    if (!r.hold_splits) return;
    if (c == 0) r.sys->hold_step_schedule(r.schedule);
    else r.sys->release_step_schedule();
  };
  const FloorVerdict v = uncontrolled_floor(problem, candidates, run.hooks.keyframes_unmet, before);
  if (!v.fell_back()) return;
  run.log.say(v.why);
  r.fallback = v.why;
  r.z = v.chosen < candidates.size() ? candidates[v.chosen] : problem.initial_guess();
  if (r.hold_splits) {
    r.schedule = r.sys->step_schedule();
    r.sys->hold_step_schedule(r.schedule);
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
  run.judged_until = setup.plan.judged_until;
  if (!run.from_controls) run.friction_scales = setup.plan.friction_scales;
  for (const auto& st : stages) run.all_evaluations += std::uint64_t(std::max(st.max_evaluations, 1));
  run.z_time = setup.start.size() ? setup.start_time : scene.time;
  StrategyResult& r = run.r;
  r.tape = std::move(setup.tape);
  r.z = std::move(setup.start);
  r.time = scene.time;
  r.time.substeps = stages[0].substeps;
  r.sys = std::move(setup.system);
  r.hold_splits = scene.cloth && scene.optimizer.split_schedule == SplitSchedule::kHeld;
  if (r.hold_splits) r.schedule = std::move(setup.start_schedule);  // a resume's first stage goes on under it
  push_uniformly_first(run, stages);
  run_stages(run, stages, 0);
  windows_after_early_end(run, stages);
  press_missed_keyframes(run, stages);
  project_near_miss_at_end(run);
  release_held_forces(run);
  r.weight_scales = run.weight_scales;
  if (r.problem) r.problem->set_weight_scales({});
  keep_no_worse_than_uncontrolled(run);
  r.planned_stages = int(stages.size());
  // Every stage its own budget, or only the last stage continued from controls.bin: not the plan's share.
  if (!run.fixed_budgets && !run.from_controls) r.scaled_budget = setup.plan.scaled_budget;
  return std::move(run.r);
}

}  // namespace kf
