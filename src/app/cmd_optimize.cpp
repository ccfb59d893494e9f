// keyframe optimize SCENE: find the control forces that hit the keyframes.
#include <iostream>

#include "app/commands.h"
#include "app/optimize_job.h"
#include "core/error.h"
#include "scene/solver_choices.h"

namespace kf {

void add_optimize_options(CLI::App* sub, OptimizeOptions& o) {
  sub->add_option("--out", o.out, "run directory (default: out/<scene>/)");
  sub->add_option("--max-evaluations", o.max_evaluations,
                  "override the scene's optimizer.max_evaluations (each = one forward + one adjoint pass)")
      ->check(CLI::Range(0, 1000000));
  sub->add_option("--checkpoint-every", o.checkpoint_every,
                  "override the scene's optimizer.checkpoint_every: keep every k-th state for the adjoint pass "
                  "and recompute the rest (0 = keep all states)")
      ->check(CLI::Range(0, 10000000));
  sub->add_option("--max-memory", o.max_memory,
                  "the memory the run may use, a size such as 4G, 512M or 1.5GiB (K, M, G, T are powers of 1024; "
                  "a plain number is bytes; 0 = the default), as `simulate` takes it; overrides the scene's "
                  "optimizer.max_memory (GB) and defaults to half the machine's: when keeping every step for the "
                  "adjoint is estimated to pass it, the run checkpoints instead (same gradient, about one more "
                  "forward pass); a run that cannot fit in the machine's memory even checkpointed is refused up front");
  sub->add_option("--adjoint", o.adjoint,
                  "override the scene's optimizer.adjoint for cloth: exact (the transpose of the step's own "
                  "Jacobian) or swap (the paper's integrator-swapping approximation)")
      ->check(CLI::IsMember(adjoint_names()));
  sub->add_flag("--quiet", o.quiet, "no line per evaluation, only a progress display");
}

void exit_if_interrupted(const OptimizeOutcome& r) {
  if (r.interrupted) std::exit(kExitInterrupted);
}

void exit_if_failed(const OptimizeOutcome& r) {
  if (!r.failed) return;
  std::cerr << "keyframe: " << r.diagnosis << " (run directory " << r.dir.string() << ")\n";
  std::exit(kExitNotReached);
}

void add_optimize_command(CLI::App& app) {
  auto* sub = app.add_subcommand("optimize",
                                 "find the control forces that make the simulation hit the scene's keyframes "
                                 "(adjoint gradient + L-BFGS); writes trajectory.bin, controls.bin, "
                                 "iterations.csv, convergence.png, report.json; exits with 7 and says why when "
                                 "the keyframes were not reached");
  auto scene = std::make_shared<std::string>();
  auto opts = std::make_shared<OptimizeOptions>();
  sub->add_option("SCENE", *scene, "scene file (JSON); not needed with --resume");
  add_optimize_options(sub, *opts);
  sub->add_option("--resume", opts->resume,
                  "continue an interrupted run from RUN_DIR/controls.bin (writes into RUN_DIR)");
  sub->callback([=] {
    if (scene->empty() && opts->resume.empty()) throw CLI::RequiredError("SCENE");
    const OptimizeOutcome outcome = optimize_job(*scene, *opts);
    exit_if_interrupted(outcome);
    exit_if_failed(outcome);
  });
}

}  // namespace kf
