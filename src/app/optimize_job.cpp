#include "app/optimize_job.h"

#include <atomic>
#include <csignal>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "app/plot.h"
#include "app/body_meshes.h"
#include "app/run_dir.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/progress.h"
#include "core/trajectory.h"
#include "opt/controls_file.h"
#include "opt/measures.h"
#include "opt/optimizer.h"
#include "sim/make_system.h"

namespace kf {
namespace fs = std::filesystem;

Trajectory frames_of(const Rollout& r, const TimeSpec& t, int particles);

namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) { g_stop = true; }

// Installs SIGINT/SIGTERM handlers for its lifetime.
struct SignalGuard {
  void (*old_int)(int), (*old_term)(int);
  SignalGuard() {
    g_stop = false;
    old_int = std::signal(SIGINT, on_signal);
    old_term = std::signal(SIGTERM, on_signal);
  }
  ~SignalGuard() {
    std::signal(SIGINT, old_int);
    std::signal(SIGTERM, old_term);
  }
};

std::string format_record(int stage, const EvaluationRecord& r) {
  std::ostringstream os;
  os << (stage > 0 ? "stage " + std::to_string(stage) + " " : "") << "eval " << std::setw(4) << r.evaluation
     << "  phi " << std::scientific << std::setprecision(4) << r.phi << "  |g| " << r.grad_norm;
  for (const auto& [name, value] : r.terms) os << "  " << name << " " << value;
  os << std::fixed << std::setprecision(2) << "  " << r.seconds << " s" << (r.diverged ? "  (diverged)" : "");
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

}  // namespace

OptimizeOutcome optimize_job(const fs::path& scene_file, const OptimizeOptions& opt) {
  const bool resuming = !opt.resume.empty();
  Scene scene = resuming ? load_run_scene(opt.resume) : load_scene(scene_file);
  if (!opt.adjoint.empty()) scene.optimizer.adjoint = opt.adjoint;
  const fs::path dir = resuming ? fs::path(opt.resume) : run_dir_for(scene, opt.out);

  // The stages of coarse-to-fine continuation; a resumed run continues in the last stage.
  std::vector<StageSpec> stages = scene.optimizer.schedule;
  if (stages.empty()) stages.push_back({scene.time.substeps, scene.optimizer.max_evaluations});
  if (opt.max_evaluations >= 0)
    for (auto& s : stages) s.max_evaluations = opt.max_evaluations;
  VecX z;
  TimeSpec z_time = scene.time;
  if (resuming) {
    z = load_controls(dir / "controls.bin", &z_time.substeps);
    stages.erase(stages.begin(), stages.end() - 1);
  }
  // Build the first system before writing anything, so bad scenes leave no trace.
  TimeSpec time = scene.time;
  time.substeps = stages[0].substeps;
  auto sys = make_system(scene, time.h());
  if (!resuming) prepare_run_dir(dir, scene);

  std::ostringstream log;
  auto say = [&](const std::string& line) {
    log << line << "\n";
    if (!opt.quiet) std::cout << line << std::endl;
  };
  SignalGuard signals;
  std::vector<HistoryRow> history;
  double seconds_before = 0;
  int evaluations = 0;
  std::string status;
  bool interrupted = false;
  std::unique_ptr<Problem> problem;
  OptimizeResult res;
  for (size_t s = 0; s < stages.size() && !interrupted; ++s) {
    time.substeps = stages[s].substeps;
    if (s > 0) sys = make_system(scene, time.h());
    problem = std::make_unique<Problem>(scene, time, *sys);
    if (opt.checkpoint_every >= 0) problem->set_checkpoint_every(opt.checkpoint_every);
    z = z.size() == 0 ? problem->initial_guess() : problem->controls().remap_from(z, z_time);
    if (z.size() != problem->size())
      throw InputError((dir / "controls.bin").string() + ": holds " + std::to_string(z.size()) +
                       " controls, the scene needs " + std::to_string(problem->size()));
    z_time = time;
    const int stage_id = stages.size() > 1 ? int(s) + 1 : 0;
    say(std::string(resuming ? "resuming " : "optimising ") + scene.name + (stage_id ? " stage " + std::to_string(stage_id) : "") +
        ": " + sys->describe() + ", " + std::to_string(time.steps()) + " steps (h = " + std::to_string(time.h()) +
        " s), " + std::to_string(problem->size()) + " control variables (" + problem->controls().kind() + ")");
    OptimizerSpec spec = scene.optimizer;
    spec.max_evaluations = stages[s].max_evaluations;
    Progress progress("optimize " + scene.name, spec.max_evaluations);
    res = minimize(*problem, spec, z,
                   [&](const EvaluationRecord& r) {
                     // Quiet runs show a progress line; others print every evaluation.
                     log << format_record(stage_id, r) << "\n";
                     if (opt.quiet) progress.update(r.evaluation);
                     else std::cout << format_record(stage_id, r) << std::endl;
                     history.push_back({stage_id, time.substeps, seconds_before + r.seconds, r});
                   },
                   &g_stop);
    // Restarts after a stalled line search, from the best point, with what is left of the stage's budget.
    for (int k = 0; k < scene.optimizer.restarts && !res.interrupted; ++k) {
      const int left = stages[s].max_evaluations - int(res.history.size());
      if (res.status.rfind("stopped: line search", 0) != 0 || left < 3) break;
      say("restart " + std::to_string(k + 1) + " from objective " + std::to_string(res.phi) + ", " +
          std::to_string(left) + " evaluations left");
      OptimizerSpec rest = spec;
      rest.max_evaluations = left;
      const double before = res.seconds;
      const int used = int(res.history.size());
      const VecX best = res.z;
      const double best_phi = res.phi;
      OptimizeResult more = minimize(*problem, rest, best,
                                     [&](const EvaluationRecord& r0) {
                                       EvaluationRecord r = r0;
                                       r.evaluation += used;
                                       r.seconds += before;
                                       log << format_record(stage_id, r) << "\n";
                                       if (opt.quiet) progress.update(r.evaluation);
                                       else std::cout << format_record(stage_id, r) << std::endl;
                                       history.push_back({stage_id, time.substeps, seconds_before + r.seconds, r});
                                     },
                                     &g_stop);
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
    progress.finish();
    z = res.z;
    seconds_before += res.seconds;
    evaluations += res.evaluations;
    status = res.status;
    interrupted = res.interrupted;
  }

  // A cape blend reports its end state against the uncontrolled run (no forces) and that run's contacts.
  nlohmann::json uncontrolled_stats;
  Trajectory uncontrolled;
  if (scene.character) {
    problem->evaluate(problem->initial_guess(), nullptr);
    uncontrolled = frames_of(problem->rollout(), time, sys->particles());
    for (const auto& [name, value] : sys->run_stats()) uncontrolled_stats[name] = value;
  }
  // Re-simulate the best point to get its states, then write everything.
  problem->evaluate(z, nullptr);
  const Trajectory frames = frames_of(problem->rollout(), time, sys->particles());
  save_controls(dir / "controls.bin", z, time.substeps);
  save_trajectory(dir / "trajectory.bin", frames);
  write_body_meshes(scene, frames.frames(), dir / "meshes.bin");
  if (!history.empty()) {
    write_history_csv(dir / "iterations.csv", history, history.front().rec.terms);
    plot_csv(dir / "iterations.csv", dir / "convergence.png", scene.name + ": objective and gradient norm", 1, {3, 4});
  }
  nlohmann::json report = {{"scene", scene.name},
                           {"command", "optimize"},
                           {"system", sys->describe()},
                           {"controls", problem->controls().kind()},
                           {"control_variables", problem->size()},
                           {"steps", time.steps()},
                           {"substeps", time.substeps},
                           {"checkpoint_every", problem->checkpoint_every()},
                           {"adjoint", scene.optimizer.adjoint},
                           {"stages", stages.size()},
                           {"resumed", resuming},
                           {"status", status},
                           {"interrupted", interrupted},
                           {"evaluations", evaluations},
                           {"wall_seconds", seconds_before},
                           {"initial_objective", history.empty() ? 0.0 : history.front().rec.phi},
                           {"final_objective", problem->evaluate(z, nullptr)},
                           {"measures", figure_measures(scene, frames)}};
  nlohmann::json terms = nlohmann::json::object();
  for (const auto& [name, value] : problem->breakdown()) terms[name] = value;
  report["final_terms"] = terms;
  for (const auto& [name, value] : sys->run_stats()) report["run_stats"][name] = value;
  if (scene.character) {
    report["uncontrolled_run_stats"] = uncontrolled_stats;
    report["cape_end_state"] = cape_end_state(scene, frames, uncontrolled);
  }
  write_json(dir / "report.json", report);
  std::ostringstream tail;
  tail << status << " after " << evaluations << " evaluations in " << std::fixed << std::setprecision(2)
       << seconds_before << " s; objective " << std::scientific << report["final_objective"].get<double>();
  say(tail.str());
  if (opt.quiet) std::cout << tail.str() << std::endl;
  if (interrupted)
    say("interrupted: best controls so far saved; continue with: keyframe optimize --resume " + dir.string());
  write_file_atomic(dir / (resuming ? "log_resumed.txt" : "log.txt"), log.str());
  return {dir, interrupted};
}

}  // namespace kf
