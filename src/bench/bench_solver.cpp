// Solver sweep: the cloth step's cost against particles for each linear solver, on 1 and 2 threads,
// forward and gradient; what a motion needs of the solve (end states against the integrator's own error);
// the pinned 50 x 50 sheet beside Blender's bake when `blender` is installed, and the whole bake at that size and
// twice the resolution (beside Blender's bakes of both).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>
#include <tbb/global_control.h>

#include "adjoint/rollout.h"
#include "bench/bench_point.h"
#include "bench/bench_sweeps.h"
#include "report/plot.h"
#include "sim/make_system.h"

namespace kf {

namespace {

// The Blender anchor's sheet: 1 m^2, horizontal, one edge pinned, swinging down under gravity; fps 24 and
// 10 steps a frame. `solver`: "direct", or a PCG preconditioner with an optional tolerance (default the
// scene default 1e-8): "pcg[-TOL]" (IC(0)), "mg[-TOL]" (multigrid), "auto[-TOL]" (the scene default: IC(0)
// below 15,000 particles, multigrid from there). A position keyframe at the last frame gives the gradient
// something to carry. `cloth_keys`: more keys of the cloth block (", ..." or empty).
Scene solver_scene(int n, const std::string& solver, int frames, int substeps = 10, const std::string& cloth_keys = "") {
  std::string extra = R"("solver": "direct")";
  if (solver != "direct") {
    const auto dash = solver.find('-');
    const std::string kind = solver.substr(0, dash), tol = dash == std::string::npos ? "1e-8" : solver.substr(dash + 1);
    const std::string pre = kind == "pcg" ? "incomplete_cholesky" : kind == "mg" ? "multigrid" : "auto";
    extra = R"("solver": "pcg", "cg_preconditioner": ")" + pre + R"(", "cg_tolerance": )" + tol;
  }
  const std::string text = R"({
    "time": {"fps": 24, "substeps": )" + std::to_string(substeps) + R"(, "frames": )" + std::to_string(frames) + R"(},
    "cloth": {"nx": )" + std::to_string(n) + R"(, "ny": )" + std::to_string(n) + R"(, "width": 1.0, "height": 1.0,
              "origin": [-0.5, 1, -0.5], "u_axis": [1, 0, 0], "v_axis": [0, 0, 1], "pins": "bottom_edge", )" + extra + cloth_keys + R"(},
    "objectives": [{"type": "center_of_mass", "frame": )" + std::to_string(frames) + R"(, "target": [0, 0.8, 0], "weight": 10}],
    "controls": {"kind": "per_frame", "alpha": 0.001}
  })";
  return parse_scene(text, "bench_solver_" + std::to_string(n) + ".json");
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// One uncontrolled forward simulation of the scene (s, fastest of `repeats`); -1 when it diverged. `run`:
// its frames (simulate_frames keeps every substeps-th state).
double forward_seconds(const Scene& scene, int repeats, Rollout* run = nullptr,
                       std::vector<std::pair<std::string, double>>* stats = nullptr) {
  double best = 1e300;
  for (int r = 0; r < repeats; ++r) {
    auto sys = make_system(scene);
    VecX x0, v0;
    sys->initial_state(x0, v0);
    Rollout roll;
    const auto t0 = std::chrono::steady_clock::now();
    if (!simulate_frames(*sys, x0, v0, scene.time, roll)) return -1;
    best = std::min(best, seconds_since(t0));
    if (run) *run = std::move(roll);
    if (stats) *stats = sys->run_stats();
  }
  return best;
}

// A run statistic by name (NaN when the system did not report it).
double stat(const std::vector<std::pair<std::string, double>>& stats, const std::string& name) {
  for (const auto& [n, value] : stats)
    if (n == name) return value;
  return std::numeric_limits<double>::quiet_NaN();
}

// Blender's bake of the same sheet (s), through the anchor script; -1 when blender or the script is missing.
double blender_seconds(const std::filesystem::path& script, int n, const std::filesystem::path& out) {
  if (std::system("command -v blender > /dev/null 2>&1") != 0 || !std::filesystem::exists(script)) return -1;
  const auto csv = out / "blender_raw.csv";
  std::filesystem::remove(csv);
  const std::string cmd = "blender -b --factory-startup --python-exit-code 1 --python '" + script.string() +
                          "' -- --workload cloth --n " + std::to_string(n) + " --csv '" + csv.string() +
                          "' > '" + (out / "blender.log").string() + "' 2>&1";
  if (std::system(cmd.c_str()) != 0) return -1;
  std::ifstream in(csv);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  const auto comma = last.rfind(',');
  return comma == std::string::npos ? -1 : std::atof(last.c_str() + comma + 1);
}

// Where two runs' last positions differ: RMS and largest distance over the particles (mm).
std::pair<double, double> end_distance_mm(const VecX& a, const VecX& b) {
  double rms = 0, worst = 0;
  const int p = int(a.size() / 3);
  for (int i = 0; i < p; ++i) {
    const double d = (seg(a, i) - seg(b, i)).norm();
    rms += d * d;
    worst = std::max(worst, d);
  }
  return {1e3 * std::sqrt(rms / std::max(1, p)), 1e3 * worst};
}

// How far one run's frames are from another's (each keeps every substeps-th state): per frame the RMS
// distance over the particles (mm); returns the mean over the frames after the first and the largest.
std::pair<double, double> frames_distance_mm(const Rollout& a, int a_substeps, const Rollout& b, int b_substeps,
                                             int frames) {
  double sum = 0, worst = 0;
  for (int f = 1; f <= frames; ++f) {
    const double rms = end_distance_mm(a.x[f * a_substeps], b.x[f * b_substeps]).first;
    sum += rms;
    worst = std::max(worst, rms);
  }
  return {sum / frames, worst};
}

// What a motion needs of the step's solve: three 30 x 30 sheets over 2 s (hanging from one edge as the
// anchor does; flung up from two corners; dropped over a sphere onto the ground), each at two step lengths.
// Each run's end state against the same run solved to 1e-12, beside the integrator's own error there (the
// 1e-12 run against one at half the step).
CsvTable motion_tolerance_table(const std::vector<double>& tolerances) {
  const std::pair<const char*, const char*> sheets[] = {
      {"hang", R"("pins": "bottom_edge", "origin": [-0.5, 1, -0.5], "u_axis": [1, 0, 0], "v_axis": [0, 0, 1])"},
      {"fling", R"("pins": "top_corners", "origin": [-0.5, 1, -0.5], "u_axis": [1, 0, 0], "v_axis": [0, 0, 1],
                   "velocity": [0, 3, 2])"},
      {"drape", R"("origin": [-0.5, 0.6, 0.5], "v_axis": [0, 0, -1],
                   "colliders": [{"type": "sphere", "center": [0, 0.3, 0], "radius": 0.25, "stiffness": 2e3},
                                 {"type": "ground", "stiffness": 2e3}])"}};
  auto end_state = [](const char* sheet, int substeps, double tol) {
    std::ostringstream text;
    text << R"({"time": {"fps": 30, "substeps": )" << substeps << R"(, "frames": 60},
               "cloth": {"nx": 30, "ny": 30, "cg_tolerance": )" << tol << ", " << sheet << "}}";
    const Scene scene = parse_scene(text.str(), "bench_motion.json");
    auto sys = make_system(scene);
    VecX x0, v0;
    sys->initial_state(x0, v0);
    Rollout r;
    return simulate_frames(*sys, x0, v0, scene.time, r) ? VecX(r.x.back()) : VecX();
  };
  // One row per sheet and step: the integrator's error, then each tolerance's RMS and largest distance.
  std::vector<std::string> cols = {"sheet", "steps_per_s", "step_error_rms_mm", "step_error_max_mm"};
  for (double tol : tolerances) {
    cols.push_back("rms_mm_" + fmt(tol));
    cols.push_back("max_mm_" + fmt(tol));
  }
  CsvTable t(cols);
  for (const auto& [name, sheet] : sheets)
    for (int substeps : {2, 8}) {
      std::cerr << "bench solver: motion tolerance, " << name << ", " << 30 * substeps << " steps/s" << std::endl;
      const VecX ref = end_state(sheet, substeps, 1e-12), half = end_state(sheet, 2 * substeps, 1e-12);
      const bool ok = ref.size() > 0 && half.size() == ref.size();
      const auto [step_rms, step_max] = ok ? end_distance_mm(ref, half) : std::pair<double, double>{0, 0};
      std::vector<std::string> row = {name, std::to_string(30 * substeps), ok ? fmt(step_rms) : "nan",
                                      ok ? fmt(step_max) : "nan"};
      for (double tol : tolerances) {
        const VecX end = end_state(sheet, substeps, tol);
        const bool fine = ok && end.size() == ref.size();
        const auto [rms, worst] = fine ? end_distance_mm(end, ref) : std::pair<double, double>{0, 0};
        row.push_back(fine ? fmt(rms) : "nan");
        row.push_back(fine ? fmt(worst) : "nan");
      }
      t.add(row);
    }
  return t;
}

// Blender's bake of the 50 x 50 sheet beside ours at each tolerance: the whole 120-frame x 10-step bake,
// default threads, both the fastest of the same number of runs. Speed against error: our run at each
// tolerance, its end positions against a run solved to 1e-12 (RMS and largest distance over the particles,
// mm). Each repeat runs Blender's bake and then ours at every tolerance, so that drift in the shared machine's
// speed over the run reaches both sides alike (our bake timed 1.33 s at the end of a full sweep and 1.0 s on
// its own minutes later, the same binary). Sets `blender_s` (-1: Blender or its script not found).
CsvTable blender_side_by_side(const SolverSweepOptions& o, const std::filesystem::path& out, double& blender_s) {
  Rollout reference;
  forward_seconds(solver_scene(o.blender_n, "pcg-1e-12", 120), 1, &reference);
  const int tols = int(o.blender_tolerances.size());
  double b = 1e300;
  std::vector<double> ours_best(tols, 1e300);
  std::vector<Rollout> ends(tols);
  for (int r = 0; r < o.repeats; ++r) {
    if (b > 0) b = std::min(b, blender_seconds(o.blender_script, o.blender_n, out));
    for (int t = 0; t < tols; ++t) {
      std::ostringstream name;
      name << "pcg-" << o.blender_tolerances[t];
      const double s = forward_seconds(solver_scene(o.blender_n, name.str(), 120), 1, &ends[t]);
      ours_best[t] = s < 0 || ours_best[t] < 0 ? -1 : std::min(ours_best[t], s);
    }
  }
  if (b < 0) std::cerr << "bench solver: blender or " << o.blender_script << " not found; no side-by-side\n";
  CsvTable side({"n", "frames", "steps", "tolerance", "ours_s", "blender_s", "blender_over_ours", "rms_mm", "max_mm"});
  for (int t = 0; t < tols; ++t) {
    const double tol = o.blender_tolerances[t], ours = ours_best[t];
    const bool ok = ours > 0 && !ends[t].x.empty() && ends[t].x.back().size() == reference.x.back().size();
    const auto [rms, worst] = ok ? end_distance_mm(ends[t].x.back(), reference.x.back()) : std::pair<double, double>{0, 0};
    side.add({std::to_string(o.blender_n), "120", "1200", fmt(tol), ok ? fmt(ours) : "nan", b > 0 ? fmt(b) : "nan",
              ok && b > 0 ? fmt(b / ours) : "nan", ok ? fmt(rms) : "nan", ok ? fmt(worst) : "nan"});
  }
  blender_s = b;
  return side;
}

void print_table(const std::string& name, const CsvTable& t) { std::cout << name << "\n" << t.excerpt() << std::endl; }

// The whole bake at 100 x 100 against the 50 x 50 one, the way `keyframe simulate` runs both (its default
// tolerance and preconditioner), repeats interleaved: the resolution sweep compares 40 steps, the start of the
// swing, which is the cheap part at 100 x 100 (fewer PCG iterations and no split steps). The split steps and
// iterations say where the larger sheet's extra time goes (the same every repeat). Blender bakes the same two
// sheets in the same loop (when it is installed, `blender_s` > 0), so its own growth with the resolution
// stands beside ours. Writes solver_bake.csv.
void whole_bake_table(const SolverSweepOptions& o, const std::filesystem::path& out, double blender_s) {
  CsvTable bake({"n", "particles", "steps", "forward_s", "ms_per_step", "over_first", "split_steps",
                 "pcg_iterations_per_step", "blender_s", "blender_over_first", "blender_over_ours"});
  const std::vector<int> sizes = {o.blender_n, 2 * o.blender_n};
  std::vector<double> best(sizes.size(), 1e300), blender(sizes.size(), blender_s > 0 ? 1e300 : -1);
  std::vector<std::vector<std::pair<std::string, double>>> stats(sizes.size());
  for (int r = 0; r < o.repeats; ++r)
    for (size_t k = 0; k < sizes.size(); ++k) {
      std::cerr << "bench solver: whole bake, n = " << sizes[k] << std::endl;
      const double s = forward_seconds(solver_scene(sizes[k], "auto-1e-4", 120), 1, nullptr, &stats[k]);
      best[k] = s < 0 || best[k] < 0 ? -1 : std::min(best[k], s);
      if (blender[k] > 0) blender[k] = std::min(blender[k], blender_seconds(o.blender_script, sizes[k], out));
    }
  for (size_t k = 0; k < sizes.size(); ++k) {
    const bool ok = best[k] > 0 && best[0] > 0, bl = blender[k] > 0 && blender[0] > 0;
    bake.add({std::to_string(sizes[k]), std::to_string(sizes[k] * sizes[k]), "1200", ok ? fmt(best[k]) : "nan",
              ok ? fmt(1e3 * best[k] / 1200) : "nan", ok ? fmt(best[k] / best[0]) : "nan",
              fmt(stat(stats[k], "split_steps")), fmt(stat(stats[k], "pcg_iterations_per_step")),
              bl ? fmt(blender[k]) : "nan", bl ? fmt(blender[k] / blender[0]) : "nan",
              bl && ok ? fmt(blender[k] / best[k]) : "nan"});
  }
  bake.write(out / "solver_bake.csv");
  print_table("solver_bake.csv", bake);
}

struct StepSetting {
  double theta, ramp, tolerance;
};

// Speed against error for the step's settings: cloth.transverse_ramp (the strain over which a stretched
// spring's transverse stiffness fades into the step's matrix; below it, part of that stiffness acts
// explicitly), cloth.theta (the step's implicitness) and the PCG tolerance. Below theta 1 only narrow ramps:
// the ramp's explicit part is no longer damped there (at 0.05 the 100 x 100 bake splits nearly every step, at
// 0.02 from theta 0.7 down half of them). The first setting is the default.
std::vector<StepSetting> step_settings() {
  std::vector<StepSetting> settings;
  for (double ramp : {0.05, 0.035, 0.02, 0.01, 0.005}) settings.push_back({1.0, ramp, 1e-4});
  for (double tol : {1e-3, 3e-3})
    for (double ramp : {0.05, 0.02, 0.005}) settings.push_back({1.0, ramp, tol});
  for (double tol : {1e-4, 1e-3, 3e-3})
    for (double ramp : {0.02, 0.005}) settings.push_back({0.8, ramp, tol});
  for (double theta : {0.7, 0.6, 0.55})
    for (double tol : {1e-4, 1e-3, 3e-3}) settings.push_back({theta, 0.005, tol});
  return settings;
}

// The whole bakes of every setting at each size (index m * settings + k), fastest of the repeats, and their
// frames. Each repeat runs every setting at both sizes, so drift in the shared machine's speed reaches both
// alike (run size after size, one such table had the 50 x 50 bakes a third slower than minutes later).
struct SettingRuns {
  std::vector<double> best;
  std::vector<Rollout> runs;
  std::vector<std::vector<std::pair<std::string, double>>> stats;
};

SettingRuns run_step_settings(const SolverSweepOptions& o, const std::vector<int>& sizes,
                              const std::vector<StepSetting>& settings) {
  const size_t ns = sizes.size(), nk = settings.size();
  SettingRuns r{std::vector<double>(ns * nk, 1e300), std::vector<Rollout>(ns * nk), {}};
  r.stats.resize(ns * nk);
  for (int rep = 0; rep < o.repeats; ++rep)
    for (size_t m = 0; m < ns; ++m)
      for (size_t k = 0; k < nk; ++k) {
        const StepSetting& st = settings[k];
        std::cerr << "bench solver: step settings, n = " << sizes[m] << ", theta " << st.theta << ", ramp "
                  << st.ramp << ", tolerance " << st.tolerance << std::endl;
        const std::string keys = ", \"transverse_ramp\": " + fmt(st.ramp) + ", \"theta\": " + fmt(st.theta);
        const size_t at = m * nk + k;
        const double sec = forward_seconds(solver_scene(sizes[m], "auto-" + fmt(st.tolerance), 120, 10, keys), 1,
                                           &r.runs[at], &r.stats[at]);
        r.best[at] = sec < 0 || r.best[at] < 0 ? -1 : std::min(r.best[at], sec);
      }
  return r;
}

// The same whole bakes at each setting, the same settings at both sizes, their frames against a run with 8
// times the steps (defaults, 1e-6). Writes solver_step_settings.csv and solver_transverse_ramp.csv (the ramp
// alone, at theta 1 and the default tolerance).
void step_settings_tables(const SolverSweepOptions& o, const std::filesystem::path& out) {
  CsvTable steps({"n", "theta", "transverse_ramp", "tolerance", "forward_s", "ms_per_step", "over_default",
                  "split_steps", "pcg_iterations_per_step", "frame_rms_mm", "worst_frame_mm"});
  CsvTable ramps({"n", "transverse_ramp", "forward_s", "ms_per_step", "over_default", "split_steps",
                  "pcg_iterations_per_step", "frame_rms_mm", "worst_frame_mm"});
  const std::vector<int> sizes = {o.blender_n, 2 * o.blender_n};
  const std::vector<StepSetting> settings = step_settings();
  const size_t ns = sizes.size(), nk = settings.size();
  std::vector<Rollout> fine(ns);
  std::vector<char> fine_ok(ns);
  for (size_t m = 0; m < ns; ++m) {
    std::cerr << "bench solver: step settings, n = " << sizes[m] << ", reference" << std::endl;
    fine_ok[m] = forward_seconds(solver_scene(sizes[m], "auto-1e-6", 120, 80), 1, &fine[m]) > 0;
  }
  const SettingRuns r = run_step_settings(o, sizes, settings);
  for (size_t m = 0; m < ns; ++m)
    for (size_t k = 0; k < nk; ++k) {
      const StepSetting& st = settings[k];
      const size_t at = m * nk + k, first = m * nk;
      const bool ok = r.best[at] > 0 && r.best[first] > 0 && fine_ok[m];
      const auto [rms, worst] = ok ? frames_distance_mm(r.runs[at], 10, fine[m], 80, 120) : std::pair<double, double>{0, 0};
      const std::vector<std::string> measured = {
          ok ? fmt(r.best[at]) : "nan", ok ? fmt(1e3 * r.best[at] / 1200) : "nan",
          ok ? fmt(r.best[at] / r.best[first]) : "nan", fmt(stat(r.stats[at], "split_steps")),
          fmt(stat(r.stats[at], "pcg_iterations_per_step")), ok ? fmt(rms) : "nan", ok ? fmt(worst) : "nan"};
      std::vector<std::string> row = {std::to_string(sizes[m]), fmt(st.theta), fmt(st.ramp), fmt(st.tolerance)};
      row.insert(row.end(), measured.begin(), measured.end());
      steps.add(row);
      if (st.theta == 1 && st.tolerance == 1e-4) {
        std::vector<std::string> ramp_row = {std::to_string(sizes[m]), fmt(st.ramp)};
        ramp_row.insert(ramp_row.end(), measured.begin(), measured.end());
        ramps.add(ramp_row);
      }
    }
  steps.write(out / "solver_step_settings.csv");
  print_table("solver_step_settings.csv", steps);
  ramps.write(out / "solver_transverse_ramp.csv");
  print_table("solver_transverse_ramp.csv", ramps);
}

// One gradient against one forward over the whole 1,200-step anchor run (the resolution sweep measures 40
// steps, where the warm starts have less history to work with). Writes solver_anchor_gradient.csv.
void anchor_gradient_table(const SolverSweepOptions& o, const BenchPointOptions& po, const std::filesystem::path& out) {
  CsvTable anchor({"n", "frames", "steps", "threads", "forward_s", "gradient_s", "gradient_over_forward"});
  for (int t : o.threads) {
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, t);
    const BenchPoint p = measure_point(solver_scene(o.blender_n, "pcg", 120), po);
    anchor.add({std::to_string(o.blender_n), "120", "1200", std::to_string(t), p.diverged ? "nan" : fmt(p.forward_s),
                p.diverged ? "nan" : fmt(p.gradient_s), p.diverged ? "nan" : fmt(p.gradient_s / p.forward_s)});
  }
  anchor.write(out / "solver_anchor_gradient.csv");
  print_table("solver_anchor_gradient.csv", anchor);
}

// The step's cost against particles, per solver and thread count, over the same frames at every size (a
// step's cost changes along the motion: the first steps, a flat sheet at rest, are the cheapest).
CsvTable resolution_sweep(const SolverSweepOptions& o, const BenchPointOptions& po) {
  std::vector<std::string> cols = {"n", "particles"};
  for (const auto& s : o.solvers)
    for (int t : o.threads)
      for (const char* what : {"forward_ms", "gradient_ms", "gradient_over_forward"})
        cols.push_back(s + "_t" + std::to_string(t) + "_" + what);
  CsvTable table(cols);
  for (int n : o.resolutions) {
    std::vector<std::string> row = {std::to_string(n), std::to_string(n * n)};
    for (const auto& s : o.solvers)
      for (int t : o.threads) {
        if (s == "direct" && n > o.direct_max_n) {  // a factor per step: minutes at these sizes
          for (int c = 0; c < 3; ++c) row.push_back("nan");
          continue;
        }
        tbb::global_control threads(tbb::global_control::max_allowed_parallelism, t);
        const Scene scene = solver_scene(n, s, o.frames);
        std::cerr << "bench solver: n = " << n << ", " << s << ", " << t << " thread(s), " << o.frames << " frames"
                  << std::endl;
        const BenchPoint p = measure_point(scene, po);
        const double steps = scene.time.steps();
        const bool ok = !p.diverged;
        row.push_back(ok ? fmt(1e3 * p.forward_s / steps) : "nan");
        row.push_back(ok ? fmt(1e3 * p.gradient_s / steps) : "nan");
        row.push_back(ok ? fmt(p.gradient_s / p.forward_s) : "nan");
      }
    table.add(row);
  }
  return table;
}

// solver.csv and its two plots (forward, gradient ms per step against particles).
void write_resolution_sweep(const SolverSweepOptions& o, const CsvTable& table, const std::filesystem::path& out) {
  const auto csv = out / "solver.csv";
  table.write(csv);
  std::vector<int> fwd, grad;
  for (const auto& s : o.solvers)
    for (int t : o.threads) {
      fwd.push_back(table.col(s + "_t" + std::to_string(t) + "_forward_ms"));
      grad.push_back(table.col(s + "_t" + std::to_string(t) + "_gradient_ms"));
    }
  plot_csv(csv, out / "solver_forward.png", "cloth: forward ms per step against particles", table.col("particles"), fwd,
           true, true);
  plot_csv(csv, out / "solver_gradient.png", "cloth: gradient (forward + adjoint) ms per step against particles",
           table.col("particles"), grad, true, true);
  print_table("solver.csv", table);
}

}  // namespace

nlohmann::json bench_solver(const SolverSweepOptions& o, const std::filesystem::path& out) {
  nlohmann::json summary;
  BenchPointOptions po;
  po.repeats = o.repeats;
  if (o.blender_n > 0) {  // Blender first, then the tables built around its sheet
    double blender_s = -1;
    const CsvTable side = blender_side_by_side(o, out, blender_s);
    whole_bake_table(o, out, blender_s);
    step_settings_tables(o, out);
    anchor_gradient_table(o, po, out);
    const auto side_csv = out / "solver_blender.csv";
    side.write(side_csv);
    plot_csv(side_csv, out / "solver_blender.png",
             "50 x 50 sheet, 1200 steps: Blender's time over ours against our end-state RMS error (mm)",
             side.col("rms_mm"), {side.col("blender_over_ours")}, false, true);
    summary["blender"] = side.excerpt();
    print_table("solver_blender.csv", side);
  }
  const CsvTable table = resolution_sweep(o, po);
  write_resolution_sweep(o, table, out);
  summary["solver"] = table.excerpt();
  if (!o.motion_table) return summary;
  const CsvTable motion = motion_tolerance_table(o.motion_tolerances);
  motion.write(out / "solver_motion.csv");
  summary["motion"] = motion.excerpt();
  print_table("solver_motion.csv", motion);
  return summary;
}

}  // namespace kf
