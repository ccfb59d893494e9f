#include "app/optimize_job.h"

#include <atomic>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "app/plot.h"
#include "app/run_dir.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/progress.h"
#include "core/trajectory.h"
#include "opt/measures.h"
#include "opt/optimizer.h"
#include "sim/make_system.h"

namespace kf {
namespace fs = std::filesystem;

Trajectory frames_of(const Rollout& r, const TimeSpec& t, int particles);

namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) { g_stop = true; }

std::string format_record(const EvaluationRecord& r) {
  std::ostringstream os;
  os << "eval " << std::setw(4) << r.evaluation << "  phi " << std::scientific << std::setprecision(4) << r.phi
     << "  |g| " << r.grad_norm;
  for (const auto& [name, value] : r.terms) os << "  " << name << " " << value;
  os << std::fixed << std::setprecision(2) << "  " << r.seconds << " s" << (r.diverged ? "  (diverged)" : "");
  return os.str();
}

void write_history_csv(const fs::path& path, const OptimizeResult& res) {
  std::ostringstream os;
  os << "evaluation,seconds,phi,grad_norm";
  const auto& first = res.history.front().terms;
  for (const auto& t : first) os << "," << t.first;
  os << "\n" << std::setprecision(10);
  for (const auto& r : res.history) {
    os << r.evaluation << "," << r.seconds << "," << r.phi << "," << r.grad_norm;
    for (size_t k = 0; k < first.size(); ++k) os << "," << (k < r.terms.size() && !r.diverged ? r.terms[k].second : NAN);
    os << "\n";
  }
  write_file_atomic(path, os.str());
}

void save_controls(const fs::path& path, const VecX& z) {
  write_stream_atomic(path, [&](std::ostream& out) {
    const char magic[8] = {'K', 'F', 'C', 'T', 'R', 'L', '0', '1'};
    const uint64_t n = uint64_t(z.size());
    out.write(magic, 8);
    out.write(reinterpret_cast<const char*>(&n), 8);
    out.write(reinterpret_cast<const char*>(z.data()), std::streamsize(8 * n));
  });
}

}  // namespace

fs::path optimize_job(const fs::path& scene_file, const OptimizeOptions& opt) {
  const Scene scene = load_scene(scene_file);
  auto sys = make_system(scene);
  const fs::path dir = run_dir_for(scene, opt.out);
  Problem problem(scene, scene.time, *sys);
  if (opt.checkpoint_every >= 0) problem.set_checkpoint_every(opt.checkpoint_every);
  OptimizerSpec spec = scene.optimizer;
  if (opt.max_evaluations >= 0) spec.max_evaluations = opt.max_evaluations;
  prepare_run_dir(dir, scene);

  std::ostringstream log;
  auto say = [&](const std::string& line) {
    log << line << "\n";
    if (!opt.quiet) std::cout << line << std::endl;
  };
  say("optimising " + scene.name + ": " + sys->describe() + ", " + std::to_string(scene.time.steps()) +
      " steps, " + std::to_string(problem.size()) + " control variables (" + problem.controls().kind() + ")");

  g_stop = false;
  auto old_int = std::signal(SIGINT, on_signal);
  auto old_term = std::signal(SIGTERM, on_signal);
  Progress progress("optimize " + scene.name, spec.max_evaluations);
  OptimizeResult res = minimize(problem, spec, problem.initial_guess(),
                                [&](const EvaluationRecord& r) {
                                  // Quiet runs show a progress line; others print every evaluation.
                                  log << format_record(r) << "\n";
                                  if (opt.quiet) progress.update(r.evaluation);
                                  else std::cout << format_record(r) << std::endl;
                                },
                                &g_stop);
  progress.finish();
  std::signal(SIGINT, old_int);
  std::signal(SIGTERM, old_term);

  // Re-simulate the best point to get its states.
  problem.evaluate(res.z, nullptr);
  const Trajectory frames = frames_of(problem.rollout(), scene.time, sys->particles());
  save_controls(dir / "controls.bin", res.z);
  save_trajectory(dir / "trajectory.bin", frames);
  write_history_csv(dir / "iterations.csv", res);
  plot_csv(dir / "iterations.csv", dir / "convergence.png", scene.name + ": objective and gradient norm", 1, {3, 4});
  nlohmann::json report = {{"scene", scene.name},
                           {"command", "optimize"},
                           {"system", sys->describe()},
                           {"controls", problem.controls().kind()},
                           {"control_variables", problem.size()},
                           {"steps", scene.time.steps()},
                           {"checkpoint_every", problem.checkpoint_every()},
                           {"status", res.status},
                           {"interrupted", res.interrupted},
                           {"evaluations", res.evaluations},
                           {"wall_seconds", res.seconds},
                           {"initial_objective", res.history.empty() ? 0.0 : res.history.front().phi},
                           {"final_objective", res.phi},
                           {"measures", figure_measures(scene, frames)}};
  nlohmann::json terms = nlohmann::json::object();
  for (const auto& [name, value] : problem.breakdown()) terms[name] = value;
  report["final_terms"] = terms;
  write_json(dir / "report.json", report);
  std::ostringstream tail;
  tail << res.status << " after " << res.evaluations << " evaluations in " << std::fixed << std::setprecision(2)
       << res.seconds << " s; objective " << std::scientific << res.phi;
  say(tail.str());
  write_file_atomic(dir / "log.txt", log.str());
  if (res.interrupted) say("interrupted: best controls so far saved in " + (dir / "controls.bin").string());
  return dir;
}

}  // namespace kf
