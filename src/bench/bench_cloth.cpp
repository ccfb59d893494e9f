// Cloth sweeps: how step length, resolution, PCG tolerance and control kind trade speed for error.
#include <functional>
#include <iostream>

#include "bench/bench_point.h"
#include "bench/bench_sweeps.h"
#include "report/plot.h"
#include "core/atomic_file.h"

namespace kf {

namespace {

// A square sheet pinned at its top corners, pushed toward a centre-of-mass and a corner keyframe.
Scene cloth_bench_scene(int n, int substeps, double cg_tolerance, const std::string& controls, int frames) {
  const std::string text = R"({
    "time": {"fps": 30, "substeps": )" + std::to_string(substeps) + R"(, "frames": )" + std::to_string(frames) + R"(},
    "cloth": {"nx": )" + std::to_string(n) + R"(, "ny": )" + std::to_string(n) + R"(, "pins": "top_corners",
              "cg_tolerance": )" + fmt(cg_tolerance) + R"(},
    "objectives": [
      {"type": "center_of_mass", "frame": )" + std::to_string(frames) + R"(, "target": [0.5, 0.45, 0.3], "weight": 10},
      {"type": "position", "frame": )" + std::to_string(frames) + R"(, "particles": [0], "targets": [[0.1, 0.2, 0.4]], "weight": 10}
    ],
    "controls": {"kind": ")" + controls + R"(", "alpha": 0.001},
    "optimizer": {"ftol_rel": 1e-10}
  })";
  return parse_scene(text, "bench_cloth_" + std::to_string(n) + ".json");
}

struct Sweep {
  std::string name, x_name;
  std::vector<std::string> columns;
};

}  // namespace

nlohmann::json bench_cloth(const ClothSweepOptions& o, const std::filesystem::path& out) {
  BenchPointOptions po;
  po.gradcheck_samples = o.gradcheck_samples;
  po.optimize_evaluations = o.optimize_evaluations;
  po.repeats = 3;  // the fastest of three: single runs of these short sweeps vary by 2x on a shared machine
  nlohmann::json summary;
  auto run = [&](const std::string& name, const std::string& x_name, const std::vector<double>& xs,
                 const std::function<Scene(double)>& make, bool log_x) {
    std::vector<std::string> cols = {x_name, "h", "particles", "cg_tolerance", "controls"};
    for (auto& c : bench_point_columns()) cols.push_back(c);
    CsvTable t(cols);
    for (double x : xs) {
      const Scene s = make(x);
      std::cerr << "bench cloth/" << name << ": " << x_name << " = " << fmt(x) << std::endl;
      const BenchPoint p = measure_point(s, po);
      std::vector<std::string> row = {fmt(x), fmt(s.time.h()), std::to_string(s.particles()),
                                      fmt(s.cloth->cg_tolerance), control_kind_name(s.controls.kind)};
      for (auto& c : bench_point_row(p)) row.push_back(c);
      t.add(row);
    }
    const auto csv = out / ("cloth_" + name + ".csv");
    t.write(csv);
    plot_csv(csv, out / ("cloth_" + name + "_time.png"), "cloth: seconds against " + x_name, t.col(x_name),
             {t.col("forward_s"), t.col("gradient_s"), t.col("optimize_s")}, true, log_x);
    plot_csv(csv, out / ("cloth_" + name + "_error.png"), "cloth: gradient error and keyframe error against " + x_name,
             t.col(x_name), {t.col("grad_rel_error"), t.col("keyframe_final")}, true, log_x);
    summary[name] = t.excerpt();
    std::cout << "cloth_" << name << ".csv\n" << t.excerpt() << std::endl;
  };
  std::vector<double> xs;
  for (int s : o.substeps) xs.push_back(s);
  run("timestep", "substeps", xs,
      [&](double s) { return cloth_bench_scene(o.base_resolution, int(s), 1e-8, "per_frame", o.frames); }, true);
  xs.clear();
  for (int n : o.resolutions) xs.push_back(n);
  run("resolution", "n", xs,
      [&](double n) { return cloth_bench_scene(int(n), o.base_substeps, 1e-8, "per_frame", o.frames); }, true);
  run("tolerance", "cg_tolerance", o.tolerances,
      [&](double tol) { return cloth_bench_scene(o.base_resolution, o.base_substeps, tol, "per_frame", o.frames); },
      true);
  // 0 = per frame, 1 = per step.
  run("controls", "per_step", {0, 1},
      [&](double k) {
        return cloth_bench_scene(o.base_resolution, o.base_substeps, 1e-8, k > 0 ? "per_step" : "per_frame", o.frames);
      },
      false);
  return summary;
}

}  // namespace kf
