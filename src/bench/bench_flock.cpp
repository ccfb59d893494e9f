// Flock sweep: cost of a gradient and of a short optimisation against the number of agents.
#include <cmath>
#include <iostream>

#include "bench/bench_point.h"
#include "bench/bench_sweeps.h"
#include "report/plot.h"
#include "scene/flock_spec.h"

namespace kf {

namespace {

// A flock walking +z, asked to shift its centre of mass sideways by the last frame.
Scene flock_bench_scene(int agents, int frames) {
  // Spawn on a lattice at 0.6 x the avoidance radius: the disc must hold the agents.
  double radius = std::sqrt(0.81 * agents / M_PI) * 1.2 + 1.0;
  while (lattice_points_in_disc(0.9, radius, agents) < agents) radius *= 1.1;
  const double ahead = 1.5 * frames / 30.0;
  const std::string text = R"({
    "time": {"fps": 30, "substeps": 1, "frames": )" + std::to_string(frames) + R"(},
    "flock": {"agents": )" + std::to_string(agents) + R"(, "spawn": {"radius": )" + fmt(radius) + R"(, "velocity": [0, 0, 1.5]}},
    "objectives": [
      {"type": "center_of_mass", "frame": )" + std::to_string(frames) + R"(, "target": [2, 0, )" + fmt(ahead + 1) + R"(], "weight": 10}
    ],
    "controls": {"kind": "per_step", "alpha": 0.01},
    "optimizer": {"ftol_rel": 1e-12}
  })";
  return parse_scene(text, "bench_flock_" + std::to_string(agents) + ".json");
}

}  // namespace

double fitted_exponent(const std::vector<double>& x, const std::vector<double>& y) {
  const int n = int(x.size());
  if (n < 2) return NAN;
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (int i = 0; i < n; ++i) {
    const double a = std::log(x[i]), b = std::log(y[i]);
    sx += a, sy += b, sxx += a * a, sxy += a * b;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

nlohmann::json bench_flock(const FlockSweepOptions& o, const std::filesystem::path& out) {
  BenchPointOptions po;
  po.optimize_evaluations = o.optimize_evaluations;
  po.repeats = 3;  // the fastest of three: one run's first pass also warms caches and the thread pool
  std::vector<std::string> cols = {"agents"};
  for (auto& c : bench_point_columns()) cols.push_back(c);
  cols.push_back("optimize_s_per_evaluation");
  CsvTable t(cols);
  std::vector<double> n, tg, to;
  for (int agents : o.agents) {
    std::cerr << "bench flock: " << agents << " agents" << std::endl;
    const BenchPoint p = measure_point(flock_bench_scene(agents, o.frames), po);
    std::vector<std::string> row = {std::to_string(agents)};
    for (auto& c : bench_point_row(p)) row.push_back(c);
    row.push_back(p.evaluations ? fmt(p.optimize_s / p.evaluations) : "");
    t.add(row);
    n.push_back(agents);
    tg.push_back(p.gradient_s);
    to.push_back(p.optimize_s);
  }
  const auto csv = out / "flock_agents.csv";
  t.write(csv);
  plot_csv(csv, out / "flock_agents.png", "flock: seconds against agents (log-log)", t.col("agents"),
           {t.col("forward_s"), t.col("gradient_s"), t.col("optimize_s")}, true, true);
  nlohmann::json j = {{"table", t.excerpt()},
                      {"gradient_exponent", fitted_exponent(n, tg)},
                      {"optimize_exponent", fitted_exponent(n, to)}};
  std::cout << "flock_agents.csv\n" << t.excerpt() << "fitted exponent: gradient " << fmt(j["gradient_exponent"])
            << ", optimisation " << fmt(j["optimize_exponent"]) << "\n" << std::endl;
  return j;
}

}  // namespace kf
