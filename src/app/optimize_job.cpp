#include "app/optimize_job.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <functional>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "adjoint/memory_estimate.h"
#include "adjoint/rollout.h"
#include "app/body_meshes.h"
#include "app/memory_budget.h"
#include "report/plot.h"
#include "app/run_dir.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/progress.h"
#include "core/trajectory.h"
#include "core/warnings.h"
#include "opt/controls_file.h"
#include "opt/diagnosis.h"
#include "report/figure_measures.h"
#include "opt/optimizer.h"
#include "opt/throw_fit.h"
#include "opt/throw_search.h"
#include "opt/windows.h"
#include "scene/reach_check.h"
#include "sim/cloth/cloth_system.h"
#include "sim/make_system.h"

namespace kf {
namespace fs = std::filesystem;

namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) { g_stop = true; }

// Installs handlers for the signals that ask a job to stop (Ctrl-C, kill, a closed terminal, Ctrl-\\) for
// its lifetime: each saves the best controls so far, as SIGINT does.
struct SignalGuard {
  static constexpr int kSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};
  void (*old[4])(int);
  SignalGuard() {
    g_stop = false;
    for (int k = 0; k < 4; ++k) old[k] = std::signal(kSignals[k], on_signal);
  }
  ~SignalGuard() {
    for (int k = 0; k < 4; ++k) std::signal(kSignals[k], old[k]);
  }
};

std::string format_record(int stage, const EvaluationRecord& r) {
  std::ostringstream os;
  os << (stage > 0 ? "stage " + std::to_string(stage) + " " : "") << "eval " << std::setw(4) << r.evaluation
     << "  phi " << std::scientific << std::setprecision(4) << r.phi << "  |g| " << r.grad_norm;
  for (const auto& [name, value] : r.terms) os << "  " << name << " " << value;
  os << std::fixed << std::setprecision(2) << "  " << r.seconds << " s"
     << (r.unstable ? "  (unstable)" : r.diverged ? "  (diverged)" : "");
  return os.str();
}

struct HistoryRow {
  int stage, substeps;
  double seconds;
  EvaluationRecord rec;
};

void write_history_csv(const fs::path& path, const std::vector<HistoryRow>& rows,
                       const std::vector<std::pair<std::string, double>>& names) {
  std::ostringstream os;
  os << "evaluation,seconds,phi,grad_norm,stage,substeps";
  for (const auto& t : names) os << "," << t.first;
  os << "\n" << std::setprecision(10);
  int k = 0;
  for (const auto& r : rows) {
    os << ++k << "," << r.seconds << "," << r.rec.phi << "," << r.rec.grad_norm << "," << r.stage << "," << r.substeps;
    for (size_t i = 0; i < names.size(); ++i)
      os << "," << (i < r.rec.terms.size() && !r.rec.diverged ? r.rec.terms[i].second : NAN);
    os << "\n";
  }
  write_file_atomic(path, os.str());
}

// What the job says and what it evaluates: every line goes to log.txt and, unless quiet, to stdout (a
// quiet run shows a progress line instead); every evaluation also goes to the history (iterations.csv).
class EvaluationLog {
 public:
  explicit EvaluationLog(bool quiet) : quiet_(quiet) {}
  void say(const std::string& line) {
    log_ << line << "\n";
    if (!quiet_) std::cout << line << std::endl;
  }
  // One evaluation of stage `stage_id` (0: the only stage), run at `substeps`, after `seconds_before` seconds
  // of earlier stages.
  void record(int stage_id, int substeps, double seconds_before, const EvaluationRecord& r, Progress& progress) {
    log_ << format_record(stage_id, r) << "\n";
    if (quiet_) progress.update(r.evaluation);
    else std::cout << format_record(stage_id, r) << std::endl;
    history_.push_back({stage_id, substeps, seconds_before + r.seconds, r});
  }
  const std::vector<HistoryRow>& history() const { return history_; }
  std::string text() const { return log_.str(); }

 private:
  bool quiet_;
  std::ostringstream log_;
  std::vector<HistoryRow> history_;
};

// One stage of the schedule: L-BFGS from z within spec.max_evaluations, then up to `restarts` fresh starts
// from the best point after a stalled line search, with what is left of the budget, while they make progress.
OptimizeResult run_stage(Problem& problem, OptimizerSpec spec, int restarts, const VecX& z, int stage_id,
                         int substeps, double seconds_before, EvaluationLog& elog, Progress& progress,
                         EvaluationTape& tape, const std::function<bool(const VecX&, double&)>& before_restart,
                         const std::function<bool()>& reached) {
  const int budget = spec.max_evaluations;
  int used = 0;       // evaluations of the earlier starts of this stage
  double before = 0;  // and their seconds
  const auto on_eval = [&](const EvaluationRecord& r0) {
    EvaluationRecord r = r0;
    r.evaluation += used;
    r.seconds += before;
    elog.record(stage_id, substeps, seconds_before, r, progress);
  };
  OptimizeResult res = minimize(problem, spec, z, on_eval, &g_stop, &tape, reached);
  for (int k = 0; k < restarts && !res.interrupted; ++k) {
    const int left = budget - int(res.history.size());
    if (res.status.rfind("stopped: line search", 0) != 0 || left < 3) break;
    elog.say("restart " + std::to_string(k + 1) + " from objective " + std::to_string(res.phi) + ", " +
             std::to_string(left) + " evaluations left");
    spec.max_evaluations = left;
    before = res.seconds;
    used = int(res.history.size());
    const VecX best = res.z;
    double best_phi = res.phi;
    if (before_restart && !before_restart(best, best_phi)) break;
    OptimizeResult more = minimize(problem, spec, best, on_eval, &g_stop, &tape, reached);
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

// One stage as report.json's stage_results states it.
struct StageResult {
  std::string kind;  // its controls' kind
  int substeps = 0, evaluations = 0;
  double objective_start = 0, objective_end = 0;
  std::string status;
  nlohmann::json to_json() const {
    return {{"kind", kind},
            {"substeps", substeps},
            {"evaluations", evaluations},
            {"objective_start", objective_start},
            {"objective_end", objective_end},
            {"status", status}};
  }
};

// The keyframe terms of an evaluation's breakdown (φ without the effort term).
double keyframe_terms(const std::vector<std::pair<std::string, double>>& terms) {
  double sum = 0;
  for (const auto& [name, value] : terms)
    if (name != "effort") sum += value;
  return sum;
}

// What the run shows besides its keyframes: its budget, its largest trial objective, how fast it still fell.
RunFacts run_facts(const std::string& status, const std::vector<HistoryRow>& history) {
  RunFacts f;
  f.status = status;
  f.budget = status.find("limit reached") != std::string::npos;
  if (history.empty()) return f;
  f.objective_start = history.front().rec.phi;
  f.evaluations = int(history.size());
  double best = INFINITY, best_earlier = INFINITY;
  const size_t earlier = history.size() - std::max<size_t>(1, history.size() / 10);
  for (size_t i = 0; i < history.size(); ++i) {
    f.max_objective = std::max(f.max_objective, history[i].rec.phi);
    f.unstable_trials += int(history[i].rec.unstable);
    best = std::min(best, history[i].rec.phi);
    if (i < earlier) best_earlier = std::min(best_earlier, history[i].rec.phi);
  }
  f.recent_improvement = std::isfinite(best_earlier) && best_earlier > 0 ? best / best_earlier : 1.0;
  return f;
}

// What the stages leave behind.
struct JobResult {
  EvaluationTape tape;  // every evaluation, for a resume that continues exactly where this run stopped
  VecX z;        // the best controls of the last stage
  TimeSpec time;  // its time discretisation
  std::unique_ptr<System> sys;
  std::unique_ptr<Problem> problem;
  std::string status;
  bool interrupted = false;
  int evaluations = 0;
  int capped_trials = 0;  // trials refused unsimulated after an unstable one (OptimizeResult::capped_trials)
  double seconds = 0;
  double memory_budget_gb = 0;  // the run's budget
  int auto_checkpoint_every = 0;  // spacing the budget asked for in the last stage (0: none)
  std::vector<StageResult> stages;
  Diagnosis diagnosis;
  bool hold_splits = false;            // optimizer.split_schedule "held", on cloth
  ClothSystem::StepSchedule schedule;  // the split pattern the last stage held
  nlohmann::json throw_search;         // what the search over rigid throws found (null: none ran)
};

// The rollout budget of a problem within a run's budget (bytes): what the optimiser's vectors and `held` (the
// job's other memory) leave, and the line that says whether checkpointing is on. At least 1 byte, so a run
// over budget checkpoints as tightly as it can.
std::size_t rollout_budget(const Problem& problem, System& sys, int lbfgs_memory, std::size_t held,
                           std::size_t budget, int& every, std::string& line) {
  const std::size_t fixed = optimizer_bytes(std::size_t(problem.size()), lbfgs_memory) + held;
  const std::size_t left = budget > fixed ? budget - fixed : 1;
  int costed = 0;
  for (int n = 0; n <= problem.time().steps(); ++n) costed += problem.active(n);
  MemoryEstimate e = estimate_rollout_memory(sys, problem.time().steps(), costed);
  bool fits = false;
  every = checkpoint_spacing_for(e, left, fits);
  e.base = fixed;
  std::ostringstream os;
  os << std::fixed << std::setprecision(2) << "memory: estimate " << e.bytes(0) / 1e9
     << " GB keeping every step, budget " << budget / 1e9 << " GB";
  if (every > 0)
    os << ": checkpointing every " << every << " steps (estimate " << e.bytes(every) / 1e9 << " GB"
       << (fits ? ")" : ", still over the budget)");
  line = os.str();
  return left;
}

// The uncontrolled run (the initial guess: no force, the scene's own initial velocities): the keyframes'
// errors before, and for a cape blend the end state it is measured against.
struct UncontrolledRun {
  double keyframes = 0;  // the keyframe terms of φ (all of φ if it diverged)
  Trajectory frames;
  nlohmann::json stats;
  nlohmann::json measures;
};

UncontrolledRun run_uncontrolled(const Scene& scene, JobResult& job) {
  Problem& problem = *job.problem;
  UncontrolledRun u;
  const double objective = problem.evaluate(problem.initial_guess(), nullptr);
  u.keyframes = problem.last_diverged() ? objective : keyframe_terms(problem.breakdown());
  u.frames = frames_of(problem.rollout(), job.time, job.sys->particles());
  for (const auto& [name, value] : job.sys->run_stats()) u.stats[name] = value;
  u.measures = figure_measures(scene, u.frames);
  return u;
}

// controls.bin, evaluations.bin (when kept), trajectory.bin, meshes.bin, iterations.csv and convergence.png.
void write_run_files(const fs::path& dir, const Scene& scene, const JobResult& job, const Trajectory& frames,
                     const EvaluationLog& elog) {
  save_controls(dir / "controls.bin", job.z, job.time.substeps);
  std::error_code ec;
  if (job.tape.complete()) save_evaluations(dir / "evaluations.bin", job.tape.records());
  else fs::remove(dir / "evaluations.bin", ec);  // too large to keep: a resume restarts from controls.bin
  save_trajectory(dir / "trajectory.bin", frames);
  write_body_meshes(scene, frames.frames(), dir / "meshes.bin");
  const auto& history = elog.history();
  if (!history.empty()) {
    write_history_csv(dir / "iterations.csv", history, history.front().rec.terms);
    plot_csv(dir / "iterations.csv", dir / "convergence.png", scene.name + ": objective and gradient norm", 1, {3, 4});
  }
}

nlohmann::json report_summary(const Scene& scene, size_t stages, bool resuming, const JobResult& job,
                              const EvaluationLog& elog, double final_objective, const Trajectory& frames) {
  const Problem& problem = *job.problem;
  const auto& history = elog.history();
  return {{"scene", scene.name},
          {"command", "optimize"},
          {"system", job.sys->describe()},
          {"controls", problem.controls().kind()},
          {"control_variables", problem.size()},
          {"steps", job.time.steps()},
          {"substeps", job.time.substeps},
          {"checkpoint_every", problem.checkpoint_every()},
          {"memory_budget_gb", job.memory_budget_gb},
          {"checkpoint_every_for_budget", job.auto_checkpoint_every},
          {"adjoint", scene.optimizer.adjoint},
          {"stages", stages},
          {"resumed", resuming},
          {"replayed_evaluations", job.tape.replayed()},
          {"status", job.status},
          {"interrupted", job.interrupted},
          {"evaluations", job.evaluations},
          {"capped_trials", job.capped_trials},
          {"wall_seconds", job.seconds},
          {"initial_objective", history.empty() ? 0.0 : history.front().rec.phi},
          {"final_objective", final_objective},
          {"measures", figure_measures(scene, frames)}};
}

// Whether the keyframes were reached and, if not, why (opt/diagnosis.h), into job.diagnosis and the report.
void diagnose_run(const Scene& scene, JobResult& job, const EvaluationLog& elog, const UncontrolledRun& before,
                  double final_objective, nlohmann::json& report) {
  Problem& problem = *job.problem;
  double effort_end = 0;
  for (const auto& [name, value] : problem.breakdown())
    if (name == "effort") effort_end = value;
  const double final_keyframes = problem.last_diverged() ? final_objective : keyframe_terms(problem.breakdown());
  const std::vector<KeyframeJudgement> keyframes = judge_keyframes(scene, before.measures, report["measures"]);
  // Under the run's checkpointing and budget: keeping every step of its gradient would hold the whole tape
  // the run itself was checkpointed to avoid, after the run.
  const Sensitivity sensitivity =
      measure_sensitivity(scene, job.time, problem.checkpoint_every(), problem.memory_budget());
  RunFacts facts = run_facts(job.status, elog.history());
  facts.flock = scene.flock.has_value();
  facts.keyframe_objective_start = before.keyframes;
  facts.keyframe_objective_end = final_keyframes;
  facts.effort_end = effort_end;
  job.diagnosis = diagnose(keyframes, sensitivity, facts);
  if (job.diagnosis.failed() && !facts.budget && !job.interrupted) {  // why the line search stalled
    facts.descent = probe_descent(problem, job.z);
    problem.evaluate(job.z, nullptr);  // the run's own rollout again, for the run statistics read after this
    job.diagnosis = diagnose(keyframes, sensitivity, facts);
    report["descent_probe"] = facts.descent.to_json();
  }
  report["diagnosis"] = job.diagnosis.to_json();
  report["diagnosis"]["keyframe_objective_start"] = before.keyframes;
  report["diagnosis"]["keyframe_objective_end"] = final_keyframes;
  report["diagnosis"]["budget_reached"] = facts.budget;
  report["diagnosis"]["max_objective_evaluated"] = facts.max_objective;
  report["keyframe_errors"] = nlohmann::json::array();
  for (const auto& k : keyframes) report["keyframe_errors"].push_back(k.to_json());
  report["sensitivity"] = sensitivity.to_json();
}

// Simulates the best point (and, for a cape blend, the uncontrolled run its end state is measured
// against), then writes controls.bin, trajectory.bin, meshes.bin, iterations.csv, convergence.png and
// report.json into dir.
nlohmann::json write_run_report(const fs::path& dir, const Scene& scene, size_t stages, bool resuming,
                                JobResult& job, const EvaluationLog& elog) {
  Problem& problem = *job.problem;
  ClothSystem* cloth = cloth_of(*job.sys);
  if (cloth) cloth->release_schedule();  // the uncontrolled run as the scene steps it
  const UncontrolledRun uncontrolled = run_uncontrolled(scene, job);
  if (cloth && job.hold_splits) cloth->hold_schedule(job.schedule);  // the result as the optimiser saw it
  const double final_objective = problem.evaluate(job.z, nullptr);
  const Trajectory frames = frames_of(problem.rollout(), job.time, job.sys->particles());
  write_run_files(dir, scene, job, frames, elog);
  nlohmann::json report = report_summary(scene, stages, resuming, job, elog, final_objective, frames);
  nlohmann::json terms = nlohmann::json::object();
  for (const auto& [name, value] : problem.breakdown()) terms[name] = value;
  report["final_terms"] = terms;
  diagnose_run(scene, job, elog, uncontrolled, final_objective, report);
  report["stage_results"] = nlohmann::json::array();
  for (const auto& st : job.stages) report["stage_results"].push_back(st.to_json());
  if (!job.throw_search.is_null()) report["throw_search"] = job.throw_search;
  for (const auto& [name, value] : job.sys->run_stats()) report["run_stats"][name] = value;
  if (scene.character) {
    report["uncontrolled_run_stats"] = uncontrolled.stats;
    report["cape_end_state"] = cape_end_state(scene, frames, uncontrolled.frames);
  }
  write_json(dir / "report.json", report);
  return report;
}

// The scene of a new run or of the run being resumed, with the command line's overrides.
Scene job_scene(const fs::path& scene_file, const OptimizeOptions& opt) {
  Scene scene = !opt.resume.empty() ? load_run_scene(opt.resume) : load_scene(scene_file);
  if (!opt.adjoint.empty()) scene.optimizer.adjoint = opt.adjoint;
  if (opt.max_seconds >= 0) scene.optimizer.max_seconds = opt.max_seconds;
  for (const std::string& w : unreachable_keyframes(scene)) warn(w);
  return scene;
}

// The memory a run needs at the checkpoint spacing that needs least: --checkpoint-every when given, else
// sqrt of the steps (the memory budget picks the spacing itself otherwise).
RunMemory least_memory(const Scene& scene, const OptimizeOptions& opt, int substeps) {
  const int every = opt.checkpoint_every > 0 ? opt.checkpoint_every
                                             : std::max(1, int(std::sqrt(double(scene.time.frames) * substeps)));
  return optimize_memory(scene, substeps, every);
}

// A run that cannot fit in the machine's memory at its most demanding stage is refused.
void check_stages_memory(const Scene& scene, const OptimizeOptions& opt, const std::vector<StageSpec>& stages) {
  RunMemory need;
  for (const auto& st : stages) {
    const RunMemory e = least_memory(scene, opt, st.substeps);
    if (e.bytes > need.bytes) need = e;
  }
  check_memory(scene, need, 0);
}

// A run that kept its evaluations resumes by replaying them from the start (the same path, budget and
// result as if it had not stopped); an older one continues its last stage from controls.bin.
void prepare_resume(const fs::path& dir, JobResult& job, TimeSpec& z_time, std::vector<StageSpec>& stages) {
  if (fs::exists(dir / "evaluations.bin")) {
    job.tape.set_replay(load_evaluations(dir / "evaluations.bin"));
    return;
  }
  job.z = load_controls(dir / "controls.bin", &z_time.substeps);
  stages.erase(stages.begin(), stages.end() - 1);
}

// Controls read from controls.bin under which the simulation diverges (or the objective is not finite)
// are bad input: refused before the optimiser starts, not reported as a run that missed its keyframes.
void check_resumed_controls(const fs::path& dir, Problem& problem, const VecX& z) {
  problem.evaluate(z, nullptr);
  if (!problem.last_diverged()) return;
  const int step = problem.rollout().diverged_at;
  std::ostringstream largest;
  largest << std::setprecision(3) << z.cwiseAbs().maxCoeff();
  const std::string why = problem.system().divergence_reason();
  throw InputError((dir / "controls.bin").string() + ": " +
                   (step >= 0 ? "the simulation diverges at step " + std::to_string(step) +
                                    (why.empty() ? std::string() : " (" + why + ")")
                              : std::string("the objective is not finite")) +
                   " under these controls (largest magnitude " + largest.str() + "), so there is no run to resume "
                   "from them");
}

// What every stage of one job shares.
struct JobContext {
  const Scene& scene;
  const OptimizeOptions& opt;
  const StagePlan& plan;
  const fs::path& dir;
  bool resuming;
  std::uint64_t max_memory;  // --max-memory in bytes (0: the scene's optimizer.max_memory)
  std::uint64_t all_evaluations;  // recorded on one tape over all stages
  EvaluationLog& elog;
};

// The stage's problem (its controls carried over from the previous stage's, or the initial guess) with its
// checkpointing and memory budget set; gives the memory line to print.
std::string set_up_stage(const JobContext& c, const StageSpec& stage, JobResult& job, TimeSpec& z_time) {
  Scene stage_scene = c.scene;  // a stage may optimise a coarser control parameterisation
  if (stage.controls) stage_scene.controls = *stage.controls;
  VecX& z = job.z;
  // The first frame of the previous stage's forces (a resumed run's controls are the scene's).
  const int z_from_frame = job.problem ? job.problem->controls().first_frame() : c.scene.controls.from_frame;
  VecX v0_before;  // the initial velocities the previous stage's kind gave, when the kind changes
  if (job.problem && job.problem->controls().forces())
    z = job.problem->controls().per_particle_forces(z);  // what remap_from takes (a lattice spread out)
  else if (job.problem && job.problem->controls().kind() != std::string(control_kind_name(stage_scene.controls.kind)))
    job.problem->controls().initial_velocity(z, v0_before);
  job.problem = std::make_unique<Problem>(stage_scene, job.time, *job.sys);
  Problem& problem = *job.problem;
  if (c.opt.checkpoint_every >= 0) problem.set_checkpoint_every(c.opt.checkpoint_every);
  const std::size_t budget = c.max_memory > 0                      ? std::size_t(c.max_memory)
                             : c.scene.optimizer.max_memory > 0 ? std::size_t(c.scene.optimizer.max_memory * 1e9)
                                                                : default_memory_budget();
  job.memory_budget_gb = budget / 1e9;
  std::string memory_line;
  // Besides the optimiser and the rollout: what the process already holds, the recorded evaluations (points
  // and gradients, for a resume) and, at the end, the run directory's two trajectories (the uncontrolled run
  // and the result).
  job.tape.expect(std::uint64_t(problem.size()), c.all_evaluations);
  const std::size_t held =
      resident_bytes() + job.tape.bytes_for(std::uint64_t(problem.size()), c.all_evaluations) +
      2 * std::size_t(c.scene.time.frames + 1) * 2 * std::size_t(job.sys->dof()) * sizeof(double);
  problem.set_memory_budget(rollout_budget(problem, *job.sys, c.scene.optimizer.memory, held, budget,
                                           job.auto_checkpoint_every, memory_line));
  if (problem.checkpoint_every() > 0) job.auto_checkpoint_every = 0;
  if (z.size() == 0) z = problem.initial_guess();
  else if (v0_before.size()) z = problem.controls().from_initial_velocity(v0_before);
  else z = problem.controls().remap_from(z, z_time, z_from_frame);
  if (z.size() != problem.size())
    throw InputError((c.dir / "controls.bin").string() + ": holds " + std::to_string(z.size()) +
                     " controls, the scene needs " + std::to_string(problem.size()));
  z_time = job.time;
  return memory_line;
}

void say_stage(const JobContext& c, const JobResult& job, int stage_id) {
  const Problem& problem = *job.problem;
  const TimeSpec& time = job.time;
  c.elog.say(std::string(c.resuming ? "resuming " : "optimising ") + c.scene.name +
             (stage_id ? " stage " + std::to_string(stage_id) : "") + ": " + job.sys->describe() + ", " +
             std::to_string(time.steps()) + " steps (h = " + std::to_string(time.h()) + " s), " +
             std::to_string(problem.size()) + " control variables (" + problem.controls().kind() +
             (problem.controls().first_frame() > 0 ? " from frame " + std::to_string(problem.controls().first_frame()) : "") +
             ")");
}

void record_stage(const OptimizeResult& res, JobResult& job) {
  job.z = res.z;
  StageResult st;
  st.kind = job.problem->controls().kind();
  st.substeps = job.time.substeps;
  st.evaluations = res.evaluations;
  st.objective_start = res.history.empty() ? res.phi : res.history.front().phi;
  st.objective_end = res.phi;
  st.status = res.status;
  job.stages.push_back(st);
  job.seconds += res.seconds;
  job.evaluations += res.evaluations;
  job.capped_trials += res.capped_trials;
  job.status = res.status;
  job.interrupted = res.interrupted;
}

// A cloth step the energy check splits is a jump in φ wherever the check flips between two trial points,
// and a line search stalls on it. Each stage simulates its start once and holds the split pattern it took;
// gives φ there.
double hold_split_schedule(JobResult& job, const VecX& z) {
  ClothSystem* cloth = cloth_of(*job.sys);
  if (!cloth || !job.hold_splits) return 0;
  cloth->release_schedule();
  const double phi = job.problem->evaluate(z, nullptr);
  job.schedule = cloth->schedule();
  cloth->hold_schedule(job.schedule);
  return phi;
}

// Before a restart from `z` (φ = phi under the held pattern): holds the pattern z takes now, when φ is no
// worse under it (phi becomes that φ); else keeps the old one and says not to restart.
bool rehold_split_schedule(JobResult& job, const VecX& z, double& phi) {
  ClothSystem::StepSchedule old = job.schedule;
  const double now = hold_split_schedule(job, z);
  if (now <= phi) {
    phi = now;
    return true;
  }
  job.schedule = std::move(old);
  cloth_of(*job.sys)->hold_schedule(job.schedule);
  return false;
}

// The search over rigid throws before a rigid first stage (opt/throw_search.h): every step is checked
// while the throws differ, then the best one's split pattern is held. Deterministic, so a resume that
// replays the run's evaluations searches again and starts where the run did.
void search_throws_first(const JobContext& c, JobResult& job) {
  constexpr int kThrowCorrections = 3;  // four flights, a small share of the search
  if (ClothSystem* cloth = cloth_of(*job.sys)) cloth->release_schedule();
  const auto t0 = std::chrono::steady_clock::now();
  const ThrowSearch found =
      search_throws(*job.problem, c.plan.throw_search, refine_fitted_throw(*job.problem, c.scene, kThrowCorrections));
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
  c.elog.say(os.str());
  job.throw_search = {{"throws", found.simulated}, {"speed_range", found.speed}, {"spin_range", found.spin},
                      {"start_objective", found.start_phi}, {"best_objective", found.phi},
                      {"fitted_objectives", found.fitted},
                      {"best_throw", std::vector<double>(found.z.data(), found.z.data() + found.z.size())},
                      {"seconds", seconds}};
  job.z = found.z;
  hold_split_schedule(job, job.z);
}

// optimizer.stop_when_reached: whether the problem's last rollout meets every keyframe's tolerance, judged
// as report.json judges the result, from the rollout's frames. A checkpointed rollout keeps too few of them to
// judge: the log says so once, and the run goes on by its other rules.
std::function<bool()> keyframes_reached(const JobContext& c, Problem& problem) {
  if (!c.scene.optimizer.stop_when_reached) return {};
  return [&c, &problem, warned = false]() mutable {
    const Rollout& r = problem.rollout();
    if (r.every != 0) {
      if (!warned) c.elog.say("stop_when_reached: not judged while the rollout is checkpointed");
      warned = true;
      return false;
    }
    const nlohmann::json m = figure_measures(c.scene, frames_of(r, problem.time(), problem.system().particles()));
    for (const KeyframeJudgement& k : judge_keyframes(c.scene, m, m))
      if (!k.met()) return false;
    return true;
  };
}

// Stage s of the coarse-to-fine continuation: its system (the first is built already), problem and optimisation.
void run_job_stage(const JobContext& c, const std::vector<StageSpec>& stages, size_t s, JobResult& job,
                   TimeSpec& z_time) {
  job.time.substeps = stages[s].substeps;
  if (s > 0) job.sys = make_system(c.scene, job.time.h());
  const bool from_controls_file = c.resuming && s == 0 && job.z.size() > 0;  // see prepare_resume
  const std::string memory_line = set_up_stage(c, stages[s], job, z_time);
  // A stage at the last one's steps goes on with its pattern: under another, its best point may lie far off.
  if (job.hold_splits && int(job.schedule.size()) == job.time.steps()) cloth_of(*job.sys)->hold_schedule(job.schedule);
  else hold_split_schedule(job, job.z);
  Problem& problem = *job.problem;
  if (from_controls_file) check_resumed_controls(c.dir, problem, job.z);
  if (s == 0 && c.plan.throw_search > 0 && !from_controls_file) search_throws_first(c, job);
  const int stage_id = stages.size() > 1 ? int(s) + 1 : 0;
  say_stage(c, job, stage_id);
  if (problem.checkpoint_every() == 0) c.elog.say(memory_line);
  OptimizerSpec spec = c.scene.optimizer;
  spec.max_evaluations = stages[s].max_evaluations;
  if (spec.first_step < 0) spec.first_step = c.plan.scaled_first_step ? problem.control_scale() : 0;
  Progress progress("optimize " + c.scene.name, spec.max_evaluations);
  const auto rehold = [&](const VecX& z, double& phi) { return rehold_split_schedule(job, z, phi); };
  const OptimizeResult res = run_stage(problem, spec, c.scene.optimizer.restarts, job.z, stage_id, job.time.substeps,
                                       job.seconds, c.elog, progress, job.tape,
                                       job.hold_splits ? rehold : std::function<bool(const VecX&, double&)>(),
                                       keyframes_reached(c, problem));
  progress.finish();
  record_stage(res, job);
}

// Runs stages[first], stages[first + 1], ...: a stage that converged or stalled early leaves its unspent
// evaluations to the next (unless --max-evaluations sets every stage's).
void run_stages(const JobContext& c, std::vector<StageSpec>& stages, size_t first, JobResult& job, TimeSpec& z_time) {
  for (size_t s = first; s < stages.size() && !job.interrupted && job.status != kKeyframesReached; ++s) {
    run_job_stage(c, stages, s, job, z_time);
    if (s + 1 < stages.size() && c.opt.max_evaluations < 0)
      stages[s + 1].max_evaluations += std::max(0, stages[s].max_evaluations - job.stages.back().evaluations);
  }
}

// After a single stage of forces that ended early, stalled or converged, with evaluations left
// (StagePlan::windows_on_early_end): the windows from no force with what is left, appended to `stages`; the
// single stage's result is kept when the windows end no lower.
void windows_after_early_end(const JobContext& c, std::vector<StageSpec>& stages, JobResult& job, TimeSpec& z_time) {
  const StageResult single = job.stages.back();
  const int left = stages[0].max_evaluations - single.evaluations;
  const bool ended_early =
      single.status.rfind("converged", 0) == 0 || single.status.rfind("stopped: line search", 0) == 0;
  if (!c.plan.windows_on_early_end || stages.size() != 1 || job.interrupted || c.resuming ||
      c.opt.max_evaluations >= 0 || !ended_early || left < std::max(10, stages[0].max_evaluations / 10))
    return;
  const VecX best = job.z;
  const ClothSystem::StepSchedule best_schedule = job.schedule;
  std::vector<StageSpec> windows = window_stages(c.scene, left);
  std::ostringstream os;
  os << "the one stage ended (" << single.status << ") at objective " << std::scientific << std::setprecision(3)
     << single.objective_end << " with " << left
     << " evaluations left: windows grown back from the last keyframe, from no force";
  c.elog.say(os.str());
  StagePlan plan = c.plan;
  plan.scaled_first_step = true;
  const JobContext wc{c.scene, c.opt, plan, c.dir, c.resuming, c.max_memory, c.all_evaluations, c.elog};
  job.problem.reset();
  job.z = VecX();
  z_time = c.scene.time;
  stages.insert(stages.end(), windows.begin(), windows.end());
  run_stages(wc, stages, 1, job, z_time);
  if (job.stages.back().objective_end < single.objective_end) return;
  c.elog.say("the windows ended no lower: the one stage's result is kept");
  job.z = best;
  job.schedule = best_schedule;
  if (ClothSystem* cloth = cloth_of(*job.sys); cloth && job.hold_splits) cloth->hold_schedule(job.schedule);
}

// The closing lines: status, objective and the diagnosis (or how to resume), on the log and, when quiet,
// on standard output.
void say_outcome(const OptimizeOptions& opt, const fs::path& dir, const JobResult& job, const nlohmann::json& report,
                 EvaluationLog& elog) {
  std::ostringstream tail;
  tail << job.status << " after " << job.evaluations << " evaluations in " << std::fixed << std::setprecision(2)
       << job.seconds << " s; objective " << std::scientific << report["final_objective"].get<double>();
  elog.say(tail.str());
  if (opt.quiet) std::cout << tail.str() << std::endl;
  if (job.interrupted)
    elog.say("interrupted: best controls so far saved; continue with: keyframe optimize --resume " + dir.string());
  else
    elog.say(job.diagnosis.line);
  if (opt.quiet && !job.interrupted && !job.diagnosis.failed()) std::cout << job.diagnosis.line << std::endl;
}

}  // namespace

OptimizeOutcome optimize_job(const fs::path& scene_file, const OptimizeOptions& opt) {
  const bool resuming = !opt.resume.empty();
  const Scene scene = job_scene(scene_file, opt);
  const fs::path dir = resuming ? fs::path(opt.resume) : run_dir_for(scene, opt.out);
  // A run that cannot fit in the machine's memory even at the checkpoint spacing that needs least is refused
  // before the stages are planned: planning a sensitive cloth simulates it once.
  // --max-memory, as simulate reads it (0 or absent: the scene's optimizer.max_memory, else half the machine's).
  const std::uint64_t max_memory = opt.max_memory.empty() ? 0 : parse_memory_size(opt.max_memory);
  check_memory(scene, least_memory(scene, opt, scene.time.substeps), 0);
  // The stages of coarse-to-fine continuation; a resumed run continues in the last stage.
  const StagePlan plan = plan_stages(scene);
  std::vector<StageSpec> stages = plan.stages;
  if (opt.max_evaluations >= 0)
    for (auto& s : stages) s.max_evaluations = opt.max_evaluations;
  JobResult job;
  job.hold_splits = scene.cloth && scene.optimizer.split_schedule == "held";
  TimeSpec z_time = scene.time;
  if (resuming) prepare_resume(dir, job, z_time, stages);
  check_stages_memory(scene, opt, stages);
  // Build the first system before writing anything, so bad scenes leave no trace.
  job.time = scene.time;
  job.time.substeps = stages[0].substeps;
  job.sys = make_system(scene, job.time.h());
  // The new run is written beside the old one and swapped in at the end (locked meanwhile), so a failed or
  // killed job leaves an existing run directory as it was.
  StagedDir staged(dir);
  const fs::path work = staged.path();
  if (resuming) staged.copy_from_target([](const std::string&) { return true; });
  else naming_run_dir(staged, [&] { prepare_run_dir(work, scene); });

  std::uint64_t all_evaluations = 0;
  for (const auto& st : stages) all_evaluations += std::uint64_t(std::max(st.max_evaluations, 1));
  EvaluationLog elog(opt.quiet);
  if (!plan.why.empty() && !resuming) elog.say(plan.why);
  SignalGuard signals;
  const JobContext context{scene, opt, plan, dir, resuming, max_memory, all_evaluations, elog};
  run_stages(context, stages, 0, job, z_time);
  windows_after_early_end(context, stages, job, z_time);

  nlohmann::json report;
  naming_run_dir(staged, [&] { report = write_run_report(work, scene, stages.size(), resuming, job, elog); });
  say_outcome(opt, dir, job, report, elog);
  commit_run_dir(staged, [&](const fs::path& w) {
    write_file_atomic(w / (resuming ? "log_resumed.txt" : "log.txt"), elog.text());
  });
  return {dir, job.interrupted, !job.interrupted && job.diagnosis.failed(), job.diagnosis.line};
}

}  // namespace kf
