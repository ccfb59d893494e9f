// keyframe gradcheck SCENE: the adjoint gradient against central finite differences.
#include <sys/stat.h>

#include <cmath>
#include <iostream>
#include <random>

#include "app/commands.h"
#include "app/uncontrolled_targets.h"
#include "core/error.h"
#include "core/file_name.h"
#include "core/warnings.h"
#include "opt/controls_file.h"
#include "opt/gradcheck.h"
#include "opt/schedule_file.h"
#include "scene/scene.h"
#include "sim/make_system.h"

namespace kf {

namespace {

struct GradcheckCommandOptions {
  std::string scene;
  int samples = 40, frames = 0, substeps = 0;
  double eps = 1e-4, dt = 0, perturb = 0.1, kink_tolerance = 1e-2;
  std::string solver;  // empty: "scene" with --at (the run's own objective), "direct" otherwise
  unsigned seed = 7;
  std::string adjoint;
  std::string at;  // a run directory whose controls.bin the check is made at
  int line = 0;    // points of φ along the negative gradient (0: none)
};

// The scene as the check runs it: shortened, resampled in time, with the requested adjoint and solve.
Scene gradcheck_scene(const GradcheckCommandOptions& o) {
  Scene scene = shortened(load_scene(o.scene), o.frames);
  if (o.substeps > 0) scene.time.substeps = o.substeps;
  if (!o.adjoint.empty()) scene.optimizer.adjoint = adjoint_kind(o.adjoint);
  const std::string solver = !o.solver.empty() ? o.solver : o.at.empty() ? "direct" : "scene";
  if (scene.cloth && solver == "direct") scene.cloth->solver = "direct";
  if (o.dt > 0) {
    const double n = 1.0 / (scene.time.fps * o.dt);
    if (std::abs(n - std::round(n)) > 1e-6 || std::round(n) < 1)
      throw InputError("--dt " + std::to_string(o.dt) + ": expected a step that divides the frame time 1/" +
                       std::to_string(scene.time.fps) + " s");
    scene.time.substeps = int(std::round(n));
  }
  resolve_uncontrolled_offsets(scene);
  return scene;
}

// φ at z - t g / |g| for t = 1e-8 .. 1e-1 (relative to max(1, |z|∞)), log-spaced: where the first points
// do not fall as t |g| predicts, the gradient describes φ only at a scale below the smallest step.
nlohmann::json objective_along_descent(Problem& problem, const VecX& z, int points) {
  VecX g(problem.size());
  const double phi0 = problem.evaluate(z, &g);
  const double gnorm = g.norm(), scale = std::max(1.0, z.lpNorm<Eigen::Infinity>());
  nlohmann::json line = nlohmann::json::array();
  if (!(gnorm > 0)) return line;
  for (int k = 0; k < points; ++k) {
    const double t = scale * std::pow(10.0, -8.0 + 7.0 * k / std::max(1, points - 1));
    const double phi = problem.evaluate(z - (t / gnorm) * g, nullptr);
    line.push_back({{"step", t}, {"phi", phi}, {"predicted", phi0 - t * gnorm}});
  }
  return line;
}

void run_gradcheck(const GradcheckCommandOptions& o) {
  const Scene scene = gradcheck_scene(o);
  auto sys = make_system(scene, scene.time.h());
  Problem problem(scene, scene.time, *sys);
  VecX z = problem.initial_guess();
  if (!o.at.empty()) {
    int substeps = 0;
    const std::filesystem::path file = std::filesystem::path(o.at) / "controls.bin";
    // Opening a FIFO would wait for a writer, and a device would never end.
    if (struct stat st {}; ::stat(file.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
      throw InputError(printable(file.string()) + ": not a regular file");
    z = load_controls(file, &substeps);
    if (z.size() != problem.size() || substeps != scene.time.substeps)
      throw InputError(o.at + "/controls.bin: holds " + std::to_string(z.size()) + " controls at " +
                       std::to_string(substeps) + " substeps; the scene's controls are " +
                       std::to_string(problem.size()) + " at " + std::to_string(scene.time.substeps));
    // The run's own objective: its controls under the step schedule its result was judged under.
    if (const StepSchedule s = run_schedule(o.at, scene, z, substeps); !s.empty()) sys->hold_step_schedule(s);
  } else {
    std::mt19937_64 rng(o.seed);
    std::normal_distribution<double> normal(0.0, o.perturb);
    for (int i = 0; i < z.size(); ++i) z[i] += normal(rng);
  }
  const GradcheckResult r = gradcheck(
      problem, z, {.samples = o.samples, .eps = o.eps, .kink_tolerance = o.kink_tolerance, .seed = o.seed});
  if (r.diverged)
    warn(printable(o.scene) + ": the simulation diverges at these controls (step " + std::to_string(r.diverged_at) +
         "): no gradient exists there and nothing was compared");
  nlohmann::json j = r.to_json();
  j["scene"] = scene.name;
  j["h"] = scene.time.h();
  j["steps"] = scene.time.steps();
  j["control_variables"] = problem.size();
  if (o.line > 0) j["line"] = objective_along_descent(problem, z, o.line);
  if (scene.cloth) {
    j["adjoint"] = adjoint_name(scene.optimizer.adjoint);
    j["solver"] = scene.cloth->solver;
  }
  std::cout << j.dump() << "\n";
}

void add_gradcheck_options(CLI::App* sub, const std::shared_ptr<GradcheckCommandOptions>& o) {
  sub->add_option("SCENE", o->scene, "scene file (JSON)")->required();
  sub->add_option("--samples", o->samples, "coordinates to compare")->check(CLI::Range(1, 100000));
  sub->add_option("--eps", o->eps, "the finite-difference step completing the first extrapolation (steps start at 4 eps), relative to max(1, |z|)")
      ->check(CLI::Range(1e-12, 1.0))
      ->capture_default_str();
  sub->add_option("--kink-tolerance", o->kink_tolerance,
                  "relative error estimate of the differences beyond which a sample is a kink")
      ->check(CLI::Range(0.0, 1e300))
      ->capture_default_str();
  sub->add_option("--solver", o->solver,
                  "cloth: the steps' linear solve during the check: direct (exact to round-off: differences of "
                  "an iteratively solved step jitter with its convergence test and measure the solver, not the "
                  "adjoint) or scene (the scene's cloth.solver and cg_tolerance); default: scene with --at (the run's "
                  "own objective), direct otherwise")
      ->check(CLI::IsMember({"direct", "scene"}));
  sub->add_option("--frames", o->frames, "shorten the scene to this many frames (keyframes move proportionally)")
      ->check(CLI::Range(1, 1000000));
  sub->add_option("--substeps", o->substeps, "override the integrator steps per frame")->check(CLI::Range(1, 100000));
  sub->add_option("--dt", o->dt, "override the time step in seconds (must divide the frame time)")
      ->check(CLI::Range(1e-7, 1.0));
  sub->add_option("--perturb", o->perturb, "scale of the random controls the check is made at (0: the scene's initial guess)")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  sub->add_option("--at", o->at, "check at a run's controls (RUN_DIR/controls.bin, under the step schedule its result was "
                                  "judged under, RUN_DIR/schedule.bin) instead of perturbed ones")
      ->excludes(sub->get_option("--perturb"));
  sub->add_option("--line", o->line, "also print φ at this many log-spaced steps along the negative gradient")
      ->check(CLI::Range(0, 1000));
  sub->add_option("--seed", o->seed, "seed for the sample and the controls")->capture_default_str();
  sub->add_option("--adjoint", o->adjoint, "cloth adjoint: exact (the step's own Jacobian) or swap (the paper's "
                                           "integrator swap); default: the scene's optimizer.adjoint")
      ->check(CLI::IsMember(adjoint_names()));
}

}  // namespace

void add_gradcheck_command(CLI::App& app) {
  auto* sub = app.add_subcommand(
      "gradcheck",
      "compare the adjoint gradient with central finite differences on a sample of control coordinates (steps 4 "
      "eps, 2 eps, eps, eps/2, ... Richardson-extrapolated, until two extrapolations agree or the objective's round-off "
      "takes over); samples whose estimates never agree to --kink-tolerance straddle a kink of the objective and "
      "are counted as kinks, not as adjoint error; fd_spread is the check's own resolution; prints one JSON "
      "object (checked, kinks, max_rel_error, cosine, rel_error_norm, fd_spread, phi_noise, ...)");
  auto o = std::make_shared<GradcheckCommandOptions>();
  add_gradcheck_options(sub, o);
  sub->callback([o] { run_gradcheck(*o); });
}

}  // namespace kf
