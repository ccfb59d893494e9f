#include "app/optimize_job.h"

#include <atomic>
#include <cmath>
#include <csignal>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "adjoint/memory_estimate.h"
#include "app/evaluation_log.h"
#include "app/memory_budget.h"
#include "app/optimize_report.h"
#include "app/run_dir.h"
#include "app/uncontrolled_targets.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/warnings.h"
#include "opt/controls_file.h"
#include "opt/evaluation_tape.h"
#include "opt/schedule_file.h"
#include "opt/strategy.h"
#include "opt/windows.h"
#include "opt/keyframes/keyframe_reach.h"
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


// The scene of a new run or of the run being resumed, with the command line's overrides.
Scene job_scene(const fs::path& scene_file, const OptimizeOptions& opt) {
  Scene scene = !opt.resume.empty() ? load_run_scene(opt.resume) : load_scene(scene_file);
  if (!opt.adjoint.empty()) scene.optimizer.adjoint = adjoint_kind(opt.adjoint);
  if (opt.max_seconds >= 0) scene.optimizer.max_seconds = opt.max_seconds;
  if (opt.stop_when_reached >= 0) scene.optimizer.stop_when_reached = opt.stop_when_reached > 0;
  resolve_uncontrolled_offsets(scene);
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

// The strategy's hooks for this job: systems built from the scene, each stage's problem checkpointed within
// the memory budget (what the process holds, the tape and the run directory's two trajectories besides the
// optimiser and the rollout), and the stop rule judged as report.json judges keyframes.
StrategyHooks job_hooks(const Scene& scene, const OptimizeOptions& opt, std::uint64_t max_memory, OptimizeRun& run) {
  StrategyHooks h;
  h.make_system = [&scene](double step) { return make_system(scene, step); };
  h.configure_problem = [&scene, &opt, max_memory, &run](Problem& problem, System& sys, std::size_t tape_bytes) {
    if (opt.checkpoint_every >= 0) problem.set_checkpoint_every(opt.checkpoint_every);
    const std::size_t budget = max_memory > 0                      ? std::size_t(max_memory)
                               : scene.optimizer.max_memory > 0 ? std::size_t(scene.optimizer.max_memory * 1e9)
                                                                : default_memory_budget();
    run.memory_budget_gb = budget / 1e9;
    const std::size_t held = resident_bytes() + tape_bytes +
                             2 * std::size_t(scene.time.frames + 1) * 2 * std::size_t(sys.dof()) * sizeof(double);
    std::string line;
    problem.set_memory_budget(
        rollout_budget(problem, sys, scene.optimizer.memory, held, budget, run.auto_checkpoint_every, line));
    if (problem.checkpoint_every() > 0) run.auto_checkpoint_every = 0;
    return line;
  };
  h.keyframes_met = [&scene](Problem& problem) { return keyframes_met(scene, problem); };
  h.keyframes_unmet = [&scene](Problem& problem) { return keyframes_unmet(scene, problem); };
  return h;
}

// A run that kept its evaluations resumes by replaying them from the start (the same path, budget and
// result as if it had not stopped); an older one continues its last stage from controls.bin, under the step
// schedule its result was judged under (schedule.bin), from the objective the run ended at.
void prepare_resume(const fs::path& dir, StrategySetup& setup) {
  if (fs::exists(dir / "evaluations.bin")) {
    setup.tape.set_replay(load_evaluations(dir / "evaluations.bin"), dir / "evaluations.bin");
    return;
  }
  setup.start = load_controls(dir / "controls.bin", &setup.start_time.substeps);
  setup.start_schedule = run_schedule(dir, setup.scene, setup.start, setup.start_time.substeps);
  setup.plan.stages.erase(setup.plan.stages.begin(), setup.plan.stages.end() - 1);
}

// The closing lines: status, objective and the diagnosis (or how to resume), on the log and, when quiet,
// on standard output.
void say_outcome(const OptimizeOptions& opt, const fs::path& dir, const OptimizeRun& run, const nlohmann::json& report,
                 EvaluationLog& elog) {
  const StrategyResult& job = run.strategy;
  std::ostringstream tail;
  tail << job.status << " after " << job.evaluations << " evaluations in " << std::fixed << std::setprecision(2)
       << job.seconds << " s; objective " << std::scientific << report["final_objective"].get<double>();
  elog.say(tail.str());
  if (opt.quiet) std::cout << tail.str() << std::endl;
  if (job.interrupted)
    elog.say("interrupted: best controls so far saved; continue with: keyframe optimize --resume " + dir.string());
  else
    elog.say(run.diagnosis.line);
  if (opt.quiet && !job.interrupted && !run.diagnosis.failed()) std::cout << run.diagnosis.line << std::endl;
}

// A signal before the first evaluation: nothing is written (the staging directory goes with its owner).
OptimizeOutcome interrupted_before_evaluating(const fs::path& dir) {
  std::cerr << "keyframe: interrupted before the first evaluation: nothing written to " << dir.string() << "\n";
  return {dir, true, false, ""};
}

}  // namespace

OptimizeOutcome optimize_job(const fs::path& scene_file, const OptimizeOptions& opt) {
  // From the start: planning, the growth probe and the throw search take time too.
  SignalGuard signals;
  const bool resuming = !opt.resume.empty();
  const Scene scene = job_scene(scene_file, opt);
  const fs::path dir = resuming ? fs::path(opt.resume) : run_dir_for(scene, opt.out);
  // A run that cannot fit in the machine's memory even at the checkpoint spacing that needs least is refused
  // before the stages are planned: planning a sensitive cloth simulates it once.
  // --max-memory, as simulate reads it (0 or absent: the scene's optimizer.max_memory, else half the machine's).
  const std::uint64_t max_memory = opt.max_memory.empty() ? 0 : parse_memory_size(opt.max_memory);
  check_memory(scene, least_memory(scene, opt, scene.time.substeps), 0);
  // The stages of coarse-to-fine continuation; a resumed run continues in the last stage.
  StrategySetup setup{scene, plan_stages(scene)};
  if (opt.max_evaluations >= 0)
    for (auto& s : setup.plan.stages) s.max_evaluations = opt.max_evaluations;
  setup.fixed_budgets = opt.max_evaluations >= 0;
  setup.resuming = resuming;
  setup.start_time = scene.time;
  setup.controls_file = dir / "controls.bin";
  setup.stop = &g_stop;
  if (resuming) prepare_resume(dir, setup);
  check_stages_memory(scene, opt, setup.plan.stages);
  // Build the first system before writing anything, so bad scenes leave no trace.
  TimeSpec first = scene.time;
  first.substeps = setup.plan.stages[0].substeps;
  setup.system = make_system(scene, first.h());
  // The new run is written beside the old one and swapped in at the end (locked meanwhile), so a failed or
  // killed job leaves an existing run directory as it was.
  if (g_stop) return interrupted_before_evaluating(dir);
  StagedDir staged(dir);
  const fs::path work = staged.path();
  if (resuming) staged.copy_from_target([](const std::string&) { return true; });
  else naming_run_dir(staged, [&] { prepare_run_dir(work, scene); });

  EvaluationLog elog(opt.quiet, "optimize " + scene.name);
  if (!setup.plan.why.empty() && !resuming) elog.say(setup.plan.why);
  OptimizeRun run;
  run.strategy = run_strategy(std::move(setup), job_hooks(scene, opt, max_memory, run), elog);
  // A run stopped during its throw search still reports the best throw it flew (a cut job's report says how far).
  if (run.strategy.interrupted && run.strategy.evaluations == 0 && !run.strategy.throw_search)
    return interrupted_before_evaluating(dir);

  nlohmann::json report;
  naming_run_dir(staged, [&] { report = write_run_report(work, scene, resuming, run, elog); });
  say_outcome(opt, dir, run, report, elog);
  commit_run_dir(staged, [&](const fs::path& w) {
    write_file_atomic(w / (resuming ? "log_resumed.txt" : "log.txt"), elog.text());
  });
  const StrategyResult& r = run.strategy;
  // A signal after the last evaluation stops nothing, but the run still exits as interrupted.
  const bool interrupted = r.interrupted || g_stop;
  return {dir, interrupted, !interrupted && run.diagnosis.failed(), run.diagnosis.line};
}

}  // namespace kf
