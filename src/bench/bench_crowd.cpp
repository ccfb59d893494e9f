// Crowd sweep: the square-then-cross figure scaled to more agents at the paper's density, optimised for a
// fixed number of evaluations in a fresh process per size: time per evaluation, whole optimisation and
// peak resident memory against agents.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>

#include "bench/bench_crowd.h"
#include "bench/bench_point.h"
#include "bench/bench_sweeps.h"
#include "report/plot.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/trajectory.h"
#include "scene/scene.h"
#include "sim/flock/neighbor_grid.h"

namespace kf {

namespace {

// The scene file `base` with `agents` agents: spawn disc (centre and radius) and every shape's polygon
// scaled by sqrt(agents / base agents) about the origin, so the density stays the figure's; coverage terms
// dropped unless kept (their radius and spacing stay, so the samples grow with the area like the agents),
// keyframe weights scaled by the same factor when asked.
// The duration stays, so a larger crowd rushes farther and packs tighter than the explicit step follows
// (100,000 agents overshoot by 2.5): every size takes its damping implicitly, 200 agents as well.
nlohmann::json scaled_scene(const nlohmann::json& base, int agents, const CrowdSweepOptions& o) {
  nlohmann::json s = base;
  const double k = std::sqrt(double(agents) / base["flock"]["agents"].get<double>());
  s["flock"]["agents"] = agents;
  s["flock"]["step"] = "implicit_damping";
  auto& spawn = s["flock"]["spawn"];
  spawn["radius"] = spawn["radius"].get<double>() * k;
  if (spawn.contains("center"))
    for (auto& c : spawn["center"]) c = c.get<double>() * k;
  if (o.stop_when_reached) s["optimizer"]["stop_when_reached"] = true;
  for (auto& objective : s["objectives"]) {
    if (o.scale_weights) objective["weight"] = objective.value("weight", 1.0) * k;
    if (objective.contains("polygon"))
      for (auto& pt : objective["polygon"])
        for (auto& c : pt) c = c.get<double>() * k;
    if (!o.coverage) objective.erase("coverage");
    else if (o.scale_weights && objective.contains("coverage"))
      objective["coverage"]["weight"] = objective["coverage"].value("weight", 0.0) * k;
  }
  return s;
}

struct ChildRun {
  double wall_s = 0;
  double cpu_s = 0;  // user + system, all threads: what a loaded machine's wall time does not show
  long peak_kb = 0;
  int status = 0;
};

// Runs `argv` in a fresh process; its peak resident set from wait4.
ChildRun run_child(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const auto t0 = std::chrono::steady_clock::now();
  const pid_t pid = fork();
  if (pid < 0) throw OutputError("bench: cannot fork");
  if (pid == 0) {
    execv(argv[0], argv.data());
    _exit(127);
  }
  int status = 0;
  rusage ru{};
  if (wait4(pid, &status, 0, &ru) != pid) throw OutputError("bench: lost the child " + args[0]);
  ChildRun r;
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.peak_kb = ru.ru_maxrss;
  r.cpu_s = double(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) + 1e-6 * double(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
  r.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return r;
}

// Mean neighbours per agent per frame of a run's trajectory within `radius` (m) on the ground: the pair
// work an evaluation does grows with it as the agents bunch.
double mean_neighbours(const std::filesystem::path& trajectory, double radius) {
  const Trajectory t = load_trajectory(trajectory);
  if (t.particles == 0 || t.x.empty()) return 0;
  NeighborGrid grid;
  double entries = 0;
  for (const VecX& x : t.x) {
    grid.build(x, radius);
    entries += grid.lists().entries();
  }
  return entries / (double(t.particles) * double(t.x.size()));
}

// Wall seconds of each evaluation, from a run's iterations.csv (its seconds column is cumulative).
std::vector<double> evaluation_seconds(const std::filesystem::path& iterations) {
  std::ifstream in(iterations);
  std::string line;
  std::vector<double> each;
  double before = 0;
  if (!std::getline(in, line)) return each;
  while (std::getline(in, line)) {
    const size_t a = line.find(','), b = line.find(',', a + 1);
    if (a == std::string::npos || b == std::string::npos) break;
    const double cumulative = std::stod(line.substr(a + 1, b - a - 1));
    each.push_back(cumulative - before);
    before = cumulative;
  }
  return each;
}

// One size of the sweep: its optimisation run in a fresh process, and the report it wrote.
struct CrowdPoint {
  int agents = 0;
  double max_gb = 0;  // 0: no memory budget
  ChildRun child;
  nlohmann::json report;
  std::vector<double> evaluation_s;                     // wall seconds of each evaluation
  double neighbours_first = 0, neighbours_final = 0;  // mean per agent per frame, uncontrolled and optimised
};

CrowdPoint run_crowd_point(const nlohmann::json& base, int agents, double max_gb, const CrowdSweepOptions& o,
                           const std::filesystem::path& work, const std::filesystem::path& self) {
  const std::string name = "square-" + std::to_string(agents) + (o.coverage ? "-coverage" : "") +
                           (o.stop_when_reached ? "-reached" : "") + (o.scale_weights ? "-weighted" : "") +
                           (max_gb > 0 ? "-budget" : "");
  const auto scene = work / (name + ".json");
  const nlohmann::json scaled = scaled_scene(base, agents, o);
  write_file_atomic(scene, scaled.dump(1) + "\n");
  const auto run = work / name;
  std::cerr << "bench crowd: " << agents << " agents" << (max_gb > 0 ? ", budget " + fmt(max_gb) + " GB" : "")
            << std::endl;
  std::vector<std::string> args = {self.string(), "optimize", scene.string(), "--out", run.string(),
                                   "--max-evaluations", std::to_string(o.evaluations), "--quiet"};
  if (max_gb > 0) {
    args.push_back("--max-memory");
    args.push_back(std::to_string(std::llround(max_gb * 1e9)));  // bytes
  }
  CrowdPoint p{agents, max_gb, run_child(args), {}, {}, 0, 0};
  std::ifstream rin(run / "report.json");
  if (!rin) throw OutputError("bench crowd: " + name + " wrote no report (exit " + std::to_string(p.child.status) + ")");
  p.report = nlohmann::json::parse(rin);
  p.evaluation_s = evaluation_seconds(run / "iterations.csv");
  // Neighbours within the widest kernel's support, at the first evaluation's controls (zero: the flock
  // simulated without them) and at the optimised ones.
  const FlockSpec flock = *load_scene(scene).flock;
  const double support = std::max({flock.avoidance.radius, flock.matching.radius, flock.centering.radius});
  const auto uncontrolled = work / (name + "-uncontrolled");
  const ChildRun sim = run_child({self.string(), "simulate", scene.string(), "--out", uncontrolled.string()});
  if (sim.status != 0) throw OutputError("bench crowd: simulating " + name + " failed (exit " + std::to_string(sim.status) + ")");
  p.neighbours_first = mean_neighbours(uncontrolled / "trajectory.bin", support);
  if (std::filesystem::exists(run / "trajectory.bin")) p.neighbours_final = mean_neighbours(run / "trajectory.bin", support);
  return p;
}

CsvTable crowd_table() {
  return CsvTable({"agents", "control_variables", "steps", "max_memory_gb", "checkpoint_every", "evaluations",
                   "optimize_s", "s_per_evaluation", "peak_mb", "bytes_per_agent_step", "inside_first",
                   "inside_second", "status", "cpu_s", "coverage_first", "coverage_second", "first_evaluation_s",
                   "last_evaluation_s", "neighbours_first", "neighbours_final"});
}

void add_crowd_row(const CrowdPoint& p, CsvTable& t) {
  const nlohmann::json& rep = p.report;
  const int evals = rep["evaluations"], steps = rep["steps"];
  const double secs = rep["wall_seconds"];
  const auto& m = rep["measures"];
  auto measure = [&](size_t k, const char* key) { return k < m.size() && m[k].contains(key) ? fmt(m[k][key]) : ""; };
  auto inside = [&](size_t k) { return measure(k, "inside_fraction"); };
  const auto& each = p.evaluation_s;
  const double per_agent_step = 1024.0 * double(p.child.peak_kb) / (double(p.agents) * steps);
  t.add({std::to_string(p.agents), std::to_string(rep["control_variables"].get<long>()), std::to_string(steps),
         fmt(rep["memory_budget_gb"]), std::to_string(rep["checkpoint_every_for_budget"].get<int>()),
         std::to_string(evals), fmt(secs), fmt(secs / std::max(evals, 1)), fmt(p.child.peak_kb / 1024.0),
         fmt(per_agent_step), inside(0), inside(1), std::to_string(p.child.status), fmt(p.child.cpu_s),
         measure(0, "coverage_fraction"), measure(1, "coverage_fraction"), each.empty() ? "" : fmt(each.front()),
         each.empty() ? "" : fmt(each.back()), fmt(p.neighbours_first), fmt(p.neighbours_final)});
}

// Agents, seconds per evaluation and peak MB of the runs without a memory budget, for the fitted exponents.
struct CrowdFit {
  std::vector<double> n, te, pk;
  void add(const CrowdPoint& p) {
    if (p.max_gb != 0) return;
    const int evals = p.report["evaluations"];
    const double secs = p.report["wall_seconds"];
    n.push_back(p.agents);
    te.push_back(secs / std::max(evals, 1));
    pk.push_back(p.child.peak_kb / 1024.0);
  }
};

nlohmann::json write_crowd_results(const CsvTable& t, const CrowdFit& fit, const nlohmann::json& points,
                                   const std::string& stem, const std::filesystem::path& out) {
  const auto csv = out / (stem + ".csv");
  t.write(csv);
  plot_csv(csv, out / (stem + "_time.png"), "crowd: seconds per evaluation and whole optimisation against agents",
           t.col("agents"), {t.col("s_per_evaluation"), t.col("optimize_s")}, true, true);
  plot_csv(csv, out / (stem + "_memory.png"), "crowd: peak resident MB against agents", t.col("agents"),
           {t.col("peak_mb")}, true, true);
  nlohmann::json j = {{"table", t.excerpt()},
                      {"evaluation_exponent", fitted_exponent(fit.n, fit.te)},
                      {"memory_exponent", fitted_exponent(fit.n, fit.pk)},
                      {"points", points}};
  std::cout << stem << ".csv\n" << t.excerpt() << "fitted exponent: per evaluation " << fmt(j["evaluation_exponent"])
            << ", peak memory " << fmt(j["memory_exponent"]) << "\n" << std::endl;
  return j;
}

}  // namespace

nlohmann::json bench_crowd(const CrowdSweepOptions& o, const std::filesystem::path& out,
                           const std::filesystem::path& self) {
  std::ifstream in(o.scene);
  if (!in) throw InputError(o.scene.string() + ": cannot read the crowd sweep's scene");
  const nlohmann::json base = nlohmann::json::parse(in);
  const std::filesystem::path work = out / "crowd";
  ensure_directory(work);
  CsvTable t = crowd_table();
  CrowdFit fit;
  nlohmann::json points = nlohmann::json::array();
  std::vector<std::pair<int, double>> sizes;
  for (int a : o.agents) sizes.emplace_back(a, 0.0);
  for (int a : o.budget_agents) sizes.emplace_back(a, o.budget_gb);
  for (const auto& [agents, max_gb] : sizes) {
    const CrowdPoint p = run_crowd_point(base, agents, max_gb, o, work, self);
    add_crowd_row(p, t);
    points.push_back({{"agents", agents}, {"max_memory_gb", max_gb}, {"exit", p.child.status},
                      {"evaluation_seconds", p.evaluation_s}, {"report", p.report}});
    fit.add(p);
  }
  const std::string stem =
      std::string(o.coverage ? "flock_crowd_coverage" : "flock_crowd") + (o.scale_weights ? "_weighted" : "");
  return write_crowd_results(t, fit, points, stem, out);
}

}  // namespace kf
