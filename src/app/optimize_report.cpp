#include "app/optimize_report.h"

#include <algorithm>
#include <cmath>

#include <iomanip>
#include <sstream>

#include "adjoint/rollout.h"
#include "app/body_meshes.h"
#include "app/run_dir.h"
#include "core/atomic_file.h"
#include "core/trajectory.h"
#include "opt/controls_file.h"
#include "opt/schedule_file.h"
#include "opt/term_breakdown.h"
#include "report/cape_end_state.h"
#include "report/figure_measures.h"
#include "report/plot.h"

namespace kf {
namespace fs = std::filesystem;

namespace {

// One stage as report.json's stage_results states it.
nlohmann::json stage_json(const StageOutcome& st) {
  return {{"kind", control_kind_name(st.kind)},
          {"substeps", st.substeps},
          {"evaluations", st.evaluations},
          {"objective_start", st.objective_start},
          {"objective_end", st.objective_end},
          {"status", st.status}};
}

nlohmann::json throw_search_json(const ThrowSearch& found, double seconds) {
  return {{"throws", found.simulated}, {"speed_range", found.speed}, {"spin_range", found.spin},
          {"start_objective", found.start_phi}, {"best_objective", found.phi},
          {"fitted_objectives", found.fitted},
          {"best_throw", std::vector<double>(found.z.data(), found.z.data() + found.z.size())},
          {"seconds", seconds}};
}

// What the run shows besides its keyframes: its budget, its largest trial objective, how fast it still fell.
RunFacts run_facts(const StrategyResult& run, const std::vector<HistoryRow>& history) {
  RunFacts f;
  f.status = run.status;
  f.budget = budget_spent(run.reason);
  f.scaled_budget = run.scaled_budget;
  f.fallback = run.fallback;
  if (history.empty()) return f;
  f.objective_start = history.front().rec.phi;
  f.evaluations = int(history.size());
  double best = INFINITY, best_earlier = INFINITY;
  const size_t earlier = history.size() - std::max<size_t>(1, history.size() / 10);
  for (size_t i = 0; i < history.size(); ++i) {
    f.max_objective = std::max(f.max_objective, history[i].rec.phi);
    f.unstable_trials += int(history[i].rec.unstable);
    f.diverged_trials += int(history[i].rec.diverged);
    best = std::min(best, history[i].rec.phi);
    if (i < earlier) best_earlier = std::min(best_earlier, history[i].rec.phi);
  }
  f.recent_improvement = std::isfinite(best_earlier) && best_earlier > 0 ? best / best_earlier : 1.0;
  return f;
}

// The uncontrolled run (the initial guess: no force, the scene's own initial velocities): the keyframes'
// errors before, and for a cape blend the end state it is measured against.
struct UncontrolledRun {
  double keyframes = 0;  // the keyframe terms of φ (all of φ if it diverged)
  Trajectory frames;
  nlohmann::json stats;
  std::vector<KeyframeMeasure> measures;
};

UncontrolledRun run_uncontrolled(const Scene& scene, StrategyResult& job) {
  Problem& problem = *job.problem;
  UncontrolledRun u;
  const double objective = problem.evaluate(problem.initial_guess(), nullptr);
  u.keyframes = problem.last_diverged() ? objective : keyframe_terms_sum(problem);
  u.frames = frames_of(problem.rollout(), job.time, job.sys->particles());
  for (const auto& [name, value] : job.sys->run_stats()) u.stats[name] = value;
  u.measures = measure_keyframes(scene, u.frames);
  return u;
}

// controls.bin, schedule.bin (the step schedule the result was judged under, when the run held one),
// evaluations.bin (when kept), trajectory.bin, meshes.bin, iterations.csv and convergence.png.
void write_run_files(const fs::path& dir, const Scene& scene, const StrategyResult& job, const Trajectory& frames,
                     const EvaluationLog& elog) {
  save_controls(dir / "controls.bin", job.z, job.time.substeps);
  save_schedule(dir / "schedule.bin", job.hold_splits ? job.schedule : StepSchedule{}, job.z, job.time.substeps,
                job.time.steps());
  std::error_code ec;
  if (job.tape.complete()) save_evaluations(dir / "evaluations.bin", job.tape.contents());
  else fs::remove(dir / "evaluations.bin", ec);  // too large to keep: a resume restarts from controls.bin
  save_trajectory(dir / "trajectory.bin", frames);
  write_body_meshes(scene, frames.frames(), dir / "meshes.bin");
  const auto& history = elog.history();
  if (!history.empty()) {
    write_history_csv(dir / "iterations.csv", history, history.front().rec.terms);
    plot_csv(dir / "iterations.csv", dir / "convergence.png", scene.name + ": objective and gradient norm", 1, {3, 4});
  }
}

nlohmann::json report_summary(const Scene& scene, bool resuming, const OptimizeRun& run, const EvaluationLog& elog,
                              double final_objective, const Trajectory& frames) {
  const StrategyResult& job = run.strategy;
  const Problem& problem = *job.problem;
  const auto& history = elog.history();
  return {{"scene", scene.name},
          {"command", "optimize"},
          {"system", job.sys->describe()},
          {"controls", problem.controls().kind_name()},
          {"control_variables", problem.size()},
          {"steps", job.time.steps()},
          {"substeps", job.time.substeps},
          {"checkpoint_every", problem.checkpoint_every()},
          {"memory_budget_gb", run.memory_budget_gb},
          {"checkpoint_every_for_budget", run.auto_checkpoint_every},
          {"adjoint", adjoint_name(scene.optimizer.adjoint)},
          {"stages", job.planned_stages},
          {"resumed", resuming},
          {"replayed_evaluations", job.tape.replayed()},
          {"status", job.status},
          {"interrupted", job.interrupted},
          {"evaluations", job.evaluations},
          // the uniform push's flights (opt/uniform_push.h), kept or not: half an evaluation each, not in the above
          {"push_flights", job.uniform_push ? job.uniform_push->simulated : 0},
          {"capped_trials", job.capped_trials},
          {"wall_seconds", job.seconds},
          {"initial_objective", history.empty() ? 0.0 : history.front().rec.phi},
          {"final_objective", final_objective},
          {"measures", figure_measures(scene, frames)}};
}

// Whether the keyframes were reached and, if not, why (opt/diagnosis.h), into job.diagnosis and the report.
void diagnose_run(const Scene& scene, OptimizeRun& run, const EvaluationLog& elog, const UncontrolledRun& before,
                  const Trajectory& frames, double final_objective, nlohmann::json& report) {
  StrategyResult& job = run.strategy;
  Problem& problem = *job.problem;
  const double effort_end = last_effort(problem).value_or(0.0);
  const double final_keyframes = problem.last_diverged() ? final_objective : keyframe_terms_sum(problem);
  const std::vector<KeyframeJudgement> keyframes =
      judge_keyframes(scene, before.measures, measure_keyframes(scene, frames));
  // Under the run's checkpointing and budget: keeping every step of its gradient would hold the whole tape
  // the run itself was checkpointed to avoid, after the run.
  const Sensitivity sensitivity =
      measure_sensitivity(scene, job.time, problem.checkpoint_every(), problem.memory_budget());
  RunFacts facts = run_facts(job, elog.history());
  facts.flock = scene.flock.has_value();
  facts.max_evaluations = scene.optimizer.max_evaluations;
  facts.keyframe_objective_start = before.keyframes;
  facts.keyframe_objective_end = final_keyframes;
  facts.effort_end = effort_end;
  run.diagnosis = diagnose(keyframes, sensitivity, facts);
  if (run.diagnosis.failed() && !facts.budget && !job.interrupted) {  // why the line search stalled
    facts.descent = probe_descent(problem, job.z);
    problem.evaluate(job.z, nullptr);  // the run's own rollout again, for the run statistics read after this
    run.diagnosis = diagnose(keyframes, sensitivity, facts);
    report["descent_probe"] = facts.descent.to_json();
  }
  report["diagnosis"] = run.diagnosis.to_json();
  report["diagnosis"]["keyframe_objective_start"] = before.keyframes;
  report["diagnosis"]["keyframe_objective_end"] = final_keyframes;
  report["diagnosis"]["budget_reached"] = facts.budget;
  report["diagnosis"]["max_objective_evaluated"] = facts.max_objective;
  report["keyframe_errors"] = nlohmann::json::array();
  for (const auto& k : keyframes) report["keyframe_errors"].push_back(k.to_json());
  report["sensitivity"] = sensitivity.to_json();
}

}  // namespace

// Simulates the best point (and, for a cape blend, the uncontrolled run its end state is measured
// against), then writes controls.bin, schedule.bin, trajectory.bin, meshes.bin, iterations.csv, convergence.png
// and report.json into dir.
nlohmann::json write_run_report(const fs::path& dir, const Scene& scene, bool resuming, OptimizeRun& run,
                                const EvaluationLog& elog) {
  StrategyResult& job = run.strategy;
  Problem& problem = *job.problem;
  job.sys->release_step_schedule();  // the uncontrolled run as the scene steps it
  const UncontrolledRun uncontrolled = run_uncontrolled(scene, job);
  job.hold_result_schedule();  // the result as the optimiser saw it
  const double final_objective = problem.evaluate(job.z, nullptr);
  const Trajectory frames = frames_of(problem.rollout(), job.time, job.sys->particles());
  write_run_files(dir, scene, job, frames, elog);
  nlohmann::json report = report_summary(scene, resuming, run, elog, final_objective, frames);
  nlohmann::json terms = nlohmann::json::object();
  for (const auto& [name, value] : problem.breakdown()) terms[name] = value;
  report["final_terms"] = terms;
  diagnose_run(scene, run, elog, uncontrolled, frames, final_objective, report);
  report["stage_results"] = nlohmann::json::array();
  for (const auto& st : job.stages) report["stage_results"].push_back(stage_json(st));
  if (!job.weight_scales.empty()) report["keyframe_weight_scales"] = job.weight_scales;
  if (!job.fallback.empty()) report["fallback"] = job.fallback;
  if (job.throw_search) report["throw_search"] = throw_search_json(*job.throw_search, job.throw_seconds);
  for (const auto& [name, value] : job.sys->run_stats()) report["run_stats"][name] = value;
  if (scene.character) {
    report["uncontrolled_run_stats"] = uncontrolled.stats;
    report["cape_end_state"] = cape_end_state(scene, frames, uncontrolled.frames);
  }
  write_json(dir / "report.json", report);
  return report;
}

bool keyframes_met(const Scene& scene, Problem& problem) {
  for (bool unmet : keyframes_unmet(scene, problem))
    if (unmet) return false;
  return true;
}

std::vector<bool> keyframes_unmet(const Scene& scene, Problem& problem) {
  return keyframes_unmet(scene, frames_of(problem.rollout(), problem.time(), problem.system().particles()));
}

}  // namespace kf
