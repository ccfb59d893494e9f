// Adjoint sweep: the exact cloth adjoint against the integrator-swapping one on the paper's cloth figures:
// the cost of a gradient, its agreement with finite differences, and the keyframe error each reaches when
// the optimiser is given the same wall time.
#include <filesystem>
#include <iostream>
#include <random>

#include "bench/bench_point.h"
#include "bench/bench_sweeps.h"
#include "report/plot.h"
#include "core/error.h"
#include "opt/gradcheck.h"
#include "opt/problem.h"
#include "sim/make_system.h"

namespace kf {

namespace {

// The gradient against finite differences at the scene's initial controls perturbed by 0.01 (at zero
// controls a sheet at rest takes steps with no velocity change, where the two adjoints coincide), with the
// linear solves tightened so the differences measure the adjoint and not the solver.
GradcheckResult check(Scene scene, int samples) {
  scene.cloth->cg_tolerance = 1e-13;
  scene.cloth->cg_max_iterations = std::max(scene.cloth->cg_max_iterations, 20000);
  auto sys = make_system(scene);
  Problem problem(scene, scene.time, *sys);
  VecX z = problem.initial_guess();
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal(0.0, 0.01);
  for (int i = 0; i < z.size(); ++i) z[i] += normal(rng);
  return gradcheck(problem, z, {.samples = samples, .eps = 1e-4});
}

}  // namespace

nlohmann::json bench_adjoint(const AdjointSweepOptions& o, const std::filesystem::path& out) {
  CsvTable t({"scene", "h", "adjoint", "steps", "control_variables", "forward_seconds", "gradient_seconds",
              "gradient_cost", "cosine", "rel_error", "max_rel_error", "fd_spread", "initial_error", "final_error",
              "optimise_seconds", "evaluations"});
  nlohmann::json summary;
  int row = 0;
  for (const std::string& name : o.scenes) {
    const std::filesystem::path file = o.scene_dir / (name + ".json");
    Scene scene;
    try {
      scene = shortened(load_scene(file), o.frames);
    } catch (const InputError& e) {
      std::cerr << "bench adjoint: skipping " << name << ": " << e.what() << std::endl;
      summary["skipped"].push_back(name + ": " + e.what());
      continue;
    }
    if (!scene.cloth) continue;
    for (const AdjointKind adjoint_choice : {AdjointKind::kExact, AdjointKind::kSwap}) {
      const char* adjoint = adjoint_name(adjoint_choice);
      scene.optimizer.adjoint = adjoint_choice;
      std::cerr << "bench adjoint: " << name << " (" << adjoint << ")" << std::endl;
      BenchPointOptions po;
      po.optimize_evaluations = 100000;
      po.optimize_seconds = o.optimize_seconds;
      po.repeats = 2;
      const BenchPoint p = measure_point(scene, po);
      const GradcheckResult c = check(scene, o.samples);
      t.add({name, fmt(scene.time.h()), adjoint, std::to_string(p.steps), std::to_string(p.control_variables),
             fmt(p.forward_s), fmt(p.gradient_s), fmt(p.gradient_s / p.forward_s), fmt(c.cosine),
             fmt(c.rel_error_norm), fmt(c.max_rel_error), fmt(c.fd_spread), fmt(p.keyframe_initial),
             fmt(p.keyframe_final), fmt(p.optimize_s), std::to_string(p.evaluations)});
      ++row;
    }
  }
  const auto csv = out / "adjoint.csv";
  t.write(csv);
  if (row > 0) {
    bar_plot_csv(csv, out / "adjoint_error.png",
                 "keyframe error before and after " + fmt(o.optimize_seconds) + " s of optimisation",
                 {t.col("scene"), t.col("adjoint")}, {t.col("initial_error"), t.col("final_error")});
    bar_plot_csv(csv, out / "adjoint_gradient.png", "one gradient: cost (forward passes) and error against finite differences",
                 {t.col("scene"), t.col("adjoint")}, {t.col("gradient_cost"), t.col("rel_error")});
  }
  summary["table"] = t.excerpt(100);
  std::cout << "adjoint.csv\n" << t.excerpt(100) << std::endl;
  return summary;
}

}  // namespace kf
