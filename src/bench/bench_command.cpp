// keyframe bench: sweep speed against error (cloth), cost against size (flock), memory against steps.
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <iostream>

#include "bench/bench_crowd.h"
#include "bench/bench_reachable.h"
#include "bench/bench_sweeps.h"
#include "app/commands.h"
#include "core/atomic_file.h"
#include "core/error.h"

namespace kf {

namespace {

struct BenchOptions {
  std::string out = "out/bench";
  std::vector<std::string> only;
  bool quick = false;
  ClothSweepOptions cloth;
  FlockSweepOptions flock;
  CrowdSweepOptions crowd;
  MemorySweepOptions memory;
  SolverSweepOptions solver;
  AdjointSweepOptions adjoint;
  RobustnessSweepOptions robustness;
  ReachableSweepOptions reachable;
  int point_steps = 0, point_every = 0, point_resolution = 16;
};

void add_cloth_sweep_options(CLI::App* sub, const std::shared_ptr<BenchOptions>& o) {
  auto* c = sub->add_option_group("cloth sweep");
  c->add_option("--substeps", o->cloth.substeps, "steps per 1/30 s frame (h = 1/(30 x substeps))")
      ->capture_default_str()->delimiter(',')->check(CLI::Range(1, 1000));
  c->add_option("--resolutions", o->cloth.resolutions, "n for n x n cloths")
      ->capture_default_str()->delimiter(',')->check(CLI::Range(2, 1024));
  c->add_option("--tolerances", o->cloth.tolerances, "PCG relative residuals")
      ->capture_default_str()->delimiter(',')->check(CLI::Range(1e-15, 1.0));
  c->add_option("--cloth-resolution", o->cloth.base_resolution, "n of the sweeps that do not vary it")
      ->capture_default_str()->check(CLI::Range(2, 1024));
  c->add_option("--cloth-substeps", o->cloth.base_substeps, "substeps of the sweeps that do not vary it")
      ->capture_default_str()->check(CLI::Range(1, 1000));
  c->add_option("--cloth-frames", o->cloth.frames, "frames simulated (1/30 s each)")
      ->capture_default_str()->check(CLI::Range(1, 100000));
  c->add_option("--samples", o->cloth.gradcheck_samples, "finite-difference coordinates per point")
      ->capture_default_str()->check(CLI::Range(0, 100000));
  c->add_option("--cloth-evaluations", o->cloth.optimize_evaluations, "L-BFGS evaluations per point")
      ->capture_default_str()->check(CLI::Range(0, 100000));
}

void add_flock_sweep_options(CLI::App* sub, const std::shared_ptr<BenchOptions>& o) {
  auto* f = sub->add_option_group("flock sweep");
  f->add_option("--agents", o->flock.agents, "flock sizes")
      ->capture_default_str()->delimiter(',')->check(CLI::Range(2, 1000000));
  f->add_option("--flock-frames", o->flock.frames, "frames simulated (1/30 s, one step each)")
      ->capture_default_str()->check(CLI::Range(1, 100000));
  f->add_option("--flock-evaluations", o->flock.optimize_evaluations, "L-BFGS evaluations per point")
      ->capture_default_str()->check(CLI::Range(0, 100000));
  auto* w = sub->add_option_group("crowd sweep (part of flock)");
  w->add_option("--crowd-scene", o->crowd.scene, "flock scene scaled to each size (spawn disc and shapes by "
                "sqrt(agents / its agents), coverage terms dropped unless --crowd-coverage)")->capture_default_str();
  w->add_option("--crowd-agents", o->crowd.agents, "crowd sizes (empty: no crowd sweep)")
      ->capture_default_str()->delimiter(',')->check(CLI::Range(2, 10000000));
  w->add_option("--crowd-evaluations", o->crowd.evaluations, "evaluations of each crowd optimisation")
      ->capture_default_str()->check(CLI::Range(1, 100000));
  w->add_option("--crowd-budget-agents", o->crowd.budget_agents, "sizes run again under --crowd-budget")
      ->capture_default_str()->delimiter(',')->check(CLI::Range(2, 10000000));
  w->add_flag("--crowd-coverage", o->crowd.coverage,
              "keep the scene's coverage terms (shapes filled); results in flock_crowd_coverage.csv and its plots");
  w->add_flag("--crowd-stop-when-reached", o->crowd.stop_when_reached,
              "stop each run at its first evaluation that meets both shapes (optimizer.stop_when_reached)");
  w->add_flag("--crowd-scale-weights", o->crowd.scale_weights,
              "scale every keyframe's weight by sqrt(agents / the scene's agents) too; results in flock_crowd_weighted.csv");
  w->add_option("--crowd-budget", o->crowd.budget_gb, "memory budget (GB) of those runs")
      ->capture_default_str()->check(CLI::Range(1e-6, 1e6));
}

void add_memory_sweep_options(CLI::App* sub, const std::shared_ptr<BenchOptions>& o) {
  auto* m = sub->add_option_group("memory sweep");
  m->add_option("--steps", o->memory.steps, "step counts (cloth, 40 steps per frame)")
      ->capture_default_str()->delimiter(',')->check(CLI::Range(40, 10000000));
  m->add_option("--checkpoint-every", o->memory.checkpoint_every, "checkpoint spacing of the checkpointed runs")
      ->capture_default_str()->check(CLI::Range(1, 10000000));
  m->add_option("--memory-resolution", o->memory.resolution, "n of the n x n cloth")
      ->capture_default_str()->check(CLI::Range(2, 1024));
}

void add_solver_sweep_options(CLI::App* sub, const std::shared_ptr<BenchOptions>& o) {
  auto* s = sub->add_option_group("solver sweep");
  s->add_option("--solver-resolutions", o->solver.resolutions, "n for n x n sheets")
      ->capture_default_str()->delimiter(',')->check(CLI::Range(2, 1024));
  s->add_option("--solvers", o->solver.solvers,
                "pcg[-TOL] (IC(0) PCG), mg[-TOL] (multigrid PCG), auto[-TOL] (the scene default), direct; TOL "
                "defaults to 1e-8")
      ->capture_default_str()
      ->delimiter(',')
      ->check([](const std::string& v) -> std::string {
        if (v == "pcg" || v == "mg" || v == "auto" || v == "direct") return "";
        const auto dash = v.find('-');
        const std::string kind = v.substr(0, dash == std::string::npos ? 0 : dash);
        char* end = nullptr;
        const double tol = kind == "pcg" || kind == "mg" || kind == "auto" ? std::strtod(v.c_str() + dash + 1, &end) : 0;
        if (end && *end == 0 && tol > 0 && tol < 1) return "";
        return "expected pcg, mg, auto (each optionally -TOL, 0 < TOL < 1) or direct, got " + v;
      });
  s->add_option("--threads", o->solver.threads, "thread counts")
      ->capture_default_str()->delimiter(',')->check(CLI::Range(1, 256));
  s->add_option("--solver-frames", o->solver.frames, "frames of every sheet (10 steps each)")
      ->capture_default_str()->check(CLI::Range(1, 100000));
  s->add_option("--direct-max-n", o->solver.direct_max_n, "largest n the direct solver runs at")
      ->capture_default_str()->check(CLI::Range(0, 1024));
  s->add_option("--blender-n", o->solver.blender_n, "sheet of the Blender side-by-side (0: none)")
      ->capture_default_str()->check(CLI::Range(0, 1024));
  s->add_option("--blender-tolerances", o->solver.blender_tolerances,
                "IC(0) PCG tolerances of our runs beside Blender's (each run's end state against a 1e-12 solve)")
      ->capture_default_str()->check(CLI::Range(1e-15, 1.0));
  s->add_option("--blender-script", o->solver.blender_script, "the anchor's Blender script")->capture_default_str();
  s->add_flag("--motion-table,!--no-motion-table", o->solver.motion_table,
              "the motion table (solver_motion.csv: three 30 x 30 sheets over 2 s against a 1e-12 solve)")
      ->capture_default_str();
}

void add_adjoint_sweep_options(CLI::App* sub, const std::shared_ptr<BenchOptions>& o) {
  auto* a = sub->add_option_group("adjoint sweep");
  a->add_option("--adjoint-scenes", o->adjoint.scenes, "cloth scenes (names in --scene-dir) compared exact vs swap")
      ->capture_default_str()->delimiter(',');
  a->add_option("--scene-dir", o->adjoint.scene_dir, "where the adjoint sweep's scenes are")->capture_default_str();
  a->add_option("--adjoint-frames", o->adjoint.frames, "shorten those scenes to this many frames (0: as they are)")
      ->capture_default_str()->check(CLI::Range(0, 100000));
  a->add_option("--adjoint-seconds", o->adjoint.optimize_seconds, "wall time of each optimisation")
      ->capture_default_str()->check(CLI::Range(0.1, 1e6));
  auto* r = sub->add_option_group("robustness suite");
  r->add_option("--robustness-dir", o->robustness.scene_dir, "the suite's scenes")->capture_default_str();
  r->add_option("--robustness-runs", o->robustness.runs_dir, "where each scene's run directory goes")
      ->capture_default_str();
  r->add_option("--robustness-scenes", o->robustness.scenes, "only these scenes (names in --robustness-dir)")
      ->delimiter(',');
  r->add_option("--robustness-evaluations", o->robustness.max_evaluations,
                "override every scene's evaluation budget (-1: the scene's own)")
      ->capture_default_str()->check(CLI::Range(-1, 1000000));
  r->add_option("--robustness-seconds", o->robustness.max_seconds,
                "wall-time limit of each scene's optimiser stages (0: the scene's own)")
      ->capture_default_str()->check(CLI::Range(0.0, 1e6));
  r->add_option("--robustness-pass-seconds", o->robustness.pass_seconds,
                "a scene passes only within this many CPU seconds of its job, where it is cut")
      ->capture_default_str()->check(CLI::Range(0.0, 1e6));
  r->add_option("--robustness-wall-seconds", o->robustness.wall_seconds, "a job is cut after this wall time too")
      ->capture_default_str()->check(CLI::Range(0.0, 1e6));
}

void add_reachable_options(CLI::App* sub, const std::shared_ptr<BenchOptions>& o) {
  auto* r = sub->add_option_group("reachable suite");
  r->add_option("--reachable-seed", o->reachable.seed, "the generator's seed")->capture_default_str();
  r->add_option("--reachable-count", o->reachable.count,
                "scenes, shared over the classes (a class outside the suite, poncho, when named: that many)")
      ->capture_default_str()->check(CLI::Range(1, 100000));
  r->add_option("--reachable-classes", o->reachable.classes, "only these classes")
      ->delimiter(',')->check(CLI::IsMember(reachable_classes()));
  r->add_option("--reachable-scenes", o->reachable.scenes, "only these scene names (\"smoke\": one a class and two more)")
      ->delimiter(',');
  r->add_option("--reachable-dir", o->reachable.scene_dir, "where the scene files are written")->capture_default_str();
  r->add_option("--reachable-runs", o->reachable.runs_dir, "where each scene's run directory goes")->capture_default_str();
  r->add_flag("--reachable-generate-only", o->reachable.generate_only, "write the scene files and stop");
  r->add_flag("--reachable-well-conditioned", o->reachable.well_conditioned,
              "draw again (up to 24 times) a sheet whose keyframes a thousandth of its variant's change moves by more "
              "than a tolerance (a knife edge); writes redraws.csv; give it its own --reachable-dir");
  r->add_option("--reachable-plot", o->reachable.plot_classes,
                "plot a class table's pass rates (scripts/reachable_classes.py's CSV) as a PNG beside it and stop");
  r->add_flag("--reachable-stop-when-reached", o->reachable.stop_when_reached,
              "every scene with optimizer.stop_when_reached on (measures the stop rule against the default)");
  r->add_option("--reachable-seconds", o->reachable.max_seconds,
                "wall-time limit of each scene's optimiser stages (0: none); a scene passes only within "
                "--reachable-pass-seconds CPU seconds")
      ->capture_default_str()->check(CLI::Range(0.0, 1e6));
  r->add_option("--reachable-pass-seconds", o->reachable.pass_seconds,
                "a scene passes only within this many CPU seconds of its job, where it is cut (with --threads 1: "
                "its seconds on an idle core)")
      ->capture_default_str()->check(CLI::Range(0.0, 1e6));
  r->add_option("--reachable-wall-seconds", o->reachable.wall_seconds, "a job is cut after this wall time too")
      ->capture_default_str()->check(CLI::Range(0.0, 1e6));
}

// The option groups of the sweeps.
void add_sweep_options(CLI::App* sub, const std::shared_ptr<BenchOptions>& o) {
  add_cloth_sweep_options(sub, o);
  add_flock_sweep_options(sub, o);
  add_memory_sweep_options(sub, o);
  add_solver_sweep_options(sub, o);
  add_adjoint_sweep_options(sub, o);
  add_reachable_options(sub, o);
}

// --quick: smaller sweeps, except where an option was given explicitly.
void apply_quick_defaults(CLI::App* sub, BenchOptions& o) {
  auto given = [&](const std::string& name) { return sub->count(name) > 0; };
  if (!given("--substeps")) o.cloth.substeps = {1, 4, 16};
  if (!given("--resolutions")) o.cloth.resolutions = {16, 24, 32};
  if (!given("--tolerances")) o.cloth.tolerances = {1e-4, 1e-6, 1e-8};
  if (!given("--cloth-frames")) o.cloth.frames = 10;
  if (!given("--samples")) o.cloth.gradcheck_samples = 12;
  if (!given("--cloth-evaluations")) o.cloth.optimize_evaluations = 15;
  if (!given("--agents")) o.flock.agents = {100, 300, 1000};
  if (!given("--flock-frames")) o.flock.frames = 20;
  if (!given("--flock-evaluations")) o.flock.optimize_evaluations = 6;
  if (!given("--crowd-agents")) o.crowd.agents = {};  // the crowd sweep only when asked for
  if (!given("--crowd-evaluations")) o.crowd.evaluations = 10;
  if (!given("--crowd-budget-agents")) o.crowd.budget_agents = {};
  if (!given("--steps")) o.memory.steps = {500, 1000, 2000, 4000};
  if (!given("--adjoint-frames")) o.adjoint.frames = 6;
  if (!given("--adjoint-seconds")) o.adjoint.optimize_seconds = 10;
  if (!given("--solver-resolutions")) o.solver.resolutions = {16, 32, 50};
}

}  // namespace

void add_bench_command(CLI::App& app) {
  auto* sub = app.add_subcommand(
      "bench",
      "sweep speed against error: cloth (time step, resolution, PCG tolerance, per-step vs per-frame control), "
      "flock (agents, fitted scaling exponent; the square-then-cross figure scaled to 100,000 agents: time per "
      "evaluation, whole optimisation, peak memory), memory (peak RSS against steps with and without adjoint "
      "checkpointing), adjoint (exact against swap on the cloth figures: gradient cost and error, keyframe error "
      "in the same wall time), solver (cloth step cost against particles per linear solver and thread count, "
      "forward and gradient, beside Blender when installed), robustness (only when named in --only: the scenes of "
      "scenes/robustness optimised at their default settings and judged by their keyframes), reachable (only when "
      "named: generated scenes whose keyframes a variant of the scene reached, bench_reachable.h); writes CSV + PNG "
      "under --out");
  auto o = std::make_shared<BenchOptions>();
  sub->add_option("--out", o->out, "output directory")->capture_default_str();
  sub->add_flag("--quick", o->quick,
                "reduced sweep (a few minutes): substeps 1,4,16; n 16,24,32; tolerances 1e-4,1e-6,1e-8; agents "
                "100,300,1000; steps 500..4000; fewer samples and evaluations. Options given explicitly win.");
  sub->add_option("--only", o->only, "run only these sweeps")
      ->check(CLI::IsMember({"cloth", "flock", "memory", "adjoint", "solver", "robustness", "reachable"}))
      ->delimiter(',');
  add_sweep_options(sub, o);
  // The child side of the memory sweep: one gradient in a fresh process.
  auto* hidden = sub->add_option_group("");
  hidden->add_option("--memory-point", o->point_steps);
  hidden->add_option("--memory-every", o->point_every);
  sub->callback([o, sub] {
    if (o->point_steps > 0) {
      memory_point(o->point_steps, o->point_every, o->memory.resolution);
      return;
    }
    if (o->quick) apply_quick_defaults(sub, *o);
    auto want = [&](const std::string& s) {
      return o->only.empty() || std::find(o->only.begin(), o->only.end(), s) != o->only.end();
    };
    const std::filesystem::path out = o->out;
    const bool reachable = std::find(o->only.begin(), o->only.end(), "reachable") != o->only.end();
    if (reachable) check_reachable_options(o->reachable);  // before anything is written
    ensure_directory(out);
    nlohmann::json summary = {{"quick", o->quick}};
    if (want("memory")) summary["memory"] = bench_memory(o->memory, out, std::filesystem::read_symlink("/proc/self/exe"));
    if (want("flock")) {
      summary["flock"] = bench_flock(o->flock, out);
      if (!o->crowd.agents.empty() || !o->crowd.budget_agents.empty())
        summary["crowd"] = bench_crowd(o->crowd, out, std::filesystem::read_symlink("/proc/self/exe"));
    }
    if (want("cloth")) summary["cloth"] = bench_cloth(o->cloth, out);
    if (want("adjoint")) summary["adjoint"] = bench_adjoint(o->adjoint, out);
    if (want("solver")) summary["solver"] = bench_solver(o->solver, out);
    // The suite takes up to an hour: only when named.
    if (std::find(o->only.begin(), o->only.end(), "robustness") != o->only.end())
      summary["robustness"] = bench_robustness(o->robustness, out);
    if (reachable) summary["reachable"] = bench_reachable(o->reachable, out);
    write_file_atomic(out / "summary.json", summary.dump(2) + "\n");
  });
}

}  // namespace kf
