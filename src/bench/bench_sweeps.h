#pragma once
// The sweeps of `keyframe bench`: each writes <out>/<name>.csv and .png and returns a short summary.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace kf {

struct ClothSweepOptions {
  std::vector<int> substeps{1, 2, 4, 8, 16, 32};   // steps per 1/30 s frame: h = 1/30 .. 1/960 s
  std::vector<int> resolutions{16, 32, 64, 128};   // n for an n x n cloth
  std::vector<double> tolerances{1e-3, 1e-4, 1e-6, 1e-8, 1e-10};  // PCG relative residual
  int base_resolution = 16, base_substeps = 4, frames = 15;
  int gradcheck_samples = 24, optimize_evaluations = 30;
};

struct SolverSweepOptions {
  std::vector<int> resolutions{16, 32, 50, 64, 100, 128};  // n for an n x n sheet
  // IC(0) PCG at 1e-8, multigrid PCG at 1e-8, the default preconditioner at the default tolerance (1e-8,
  // gradients) and at keyframe simulate's (1e-4, a scene that states none), sparse Cholesky
  std::vector<std::string> solvers{"pcg", "mg", "auto", "auto-1e-4", "direct"};
  std::vector<int> threads{1, 2};
  int frames = 4;      // frames of every sheet (10 steps each)
  int repeats = 3;     // timings are the fastest of this many runs (two-thread times vary between runs here)
  int direct_max_n = 64;  // the direct solver only up to this n
  int blender_n = 50;  // side-by-side sheet (0: none)
  // IC(0) PCG tolerances of the side-by-side (speed against error; 1e-4 is what keyframe simulate uses on
  // this scene, which states none)
  std::vector<double> blender_tolerances{1e-8, 1e-6, 1e-5, 1e-4, 1e-3};
  // Tolerances of the motion table (solver_motion.csv)
  std::vector<double> motion_tolerances{1e-8, 1e-6, 1e-4, 1e-3};
  bool motion_table = true;  // --no-motion-table clears it (the table takes most of a small sweep's time)
  // The Blender anchor's script, beside the repository (shared/ next to its root); the build sets the root.
  std::filesystem::path blender_script = std::filesystem::path(KEYFRAME_REPOSITORY) / "../shared/anchors/blender/bench.py";
};

struct FlockSweepOptions {
  std::vector<int> agents{100, 300, 1000, 3000, 10000};
  int frames = 30, optimize_evaluations = 10;
};

struct MemorySweepOptions {
  std::vector<int> steps{500, 1000, 2000, 4000, 8000};
  int checkpoint_every = 50, resolution = 16;
};

struct AdjointSweepOptions {
  std::filesystem::path scene_dir = "scenes";
  std::vector<std::string> scenes{"arch", "shapes", "ring-toss", "cape-blend"};
  int frames = 0;                 // > 0: scenes shortened to this many frames
  double optimize_seconds = 60;   // wall time each adjoint's optimisation gets
  int samples = 16;               // finite-difference coordinates per gradient check
};

struct RobustnessSweepOptions {
  std::filesystem::path scene_dir = "scenes/robustness";
  std::vector<std::string> scenes;  // names in scene_dir; empty: every scene there
  std::filesystem::path runs_dir = "out/robustness";  // each scene's run directory goes here
  int max_evaluations = -1;         // >= 0: overrides each scene's budget (a reduced run)
  double max_seconds = 0;           // > 0: each scene's optimiser stops after this wall time (0: the scene's own)
  // A scene passes only within this many CPU seconds of its whole job (every thread), where it is cut
  // (bench/job_deadline.h); with --threads 1 they are its seconds on an idle core, whatever the load.
  double pass_seconds = 180;
  double wall_seconds = 1200;       // and a job is cut after this wall time whatever its CPU seconds
};

// Robustness: each scene optimised at its own (default) settings and judged by its keyframes
// (robustness.csv: scene, strategy, the worst keyframe's error before and after, evaluations, wall and CPU
// seconds, pass;
// robustness.png; each run's report.json as reports/<scene>.json; the run directories under runs_dir).
nlohmann::json bench_robustness(const RobustnessSweepOptions& o, const std::filesystem::path& out);

// Adjoint: exact against swap on the cloth figures (adjoint.csv): gradient cost and error, and the
// keyframe error reached in the same wall time. Scenes that cannot load (a cape blend whose clips were not
// simulated) are skipped with a message.
nlohmann::json bench_adjoint(const AdjointSweepOptions& o, const std::filesystem::path& out);

// Cloth: time step, resolution, PCG tolerance, per-step vs per-frame control.
nlohmann::json bench_cloth(const ClothSweepOptions& o, const std::filesystem::path& out);
// Solver: the pinned sheet's cost per step against particles for each solver and thread count, forward and
// gradient (solver.csv, solver_*.png); what a motion needs of the solve (solver_motion.csv); with blender
// installed, the 120-frame 50 x 50 bake beside ours (solver_blender.csv).
nlohmann::json bench_solver(const SolverSweepOptions& o, const std::filesystem::path& out);
// Flock: agents against time per gradient and per short optimisation, with fitted exponents.
nlohmann::json bench_flock(const FlockSweepOptions& o, const std::filesystem::path& out);
// Peak resident memory of one cloth gradient against steps, with and without checkpointing; each
// point runs in a fresh `keyframe` process (`self` is this executable).
nlohmann::json bench_memory(const MemorySweepOptions& o, const std::filesystem::path& out,
                            const std::filesystem::path& self);
// The child side: one gradient of an n x n cloth over `steps` steps, printed as one JSON line with the
// peak resident memory (VmHWM, kB) before and after.
void memory_point(int steps, int checkpoint_every, int resolution);

// Least-squares slope of log(y) against log(x).
double fitted_exponent(const std::vector<double>& x, const std::vector<double>& y);

}  // namespace kf
