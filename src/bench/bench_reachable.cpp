// The reachable-by-construction suite: each generated scene optimised with `keyframe optimize`'s own job at
// its default settings and judged by its keyframes (opt/diagnosis.h), a table a scene and one a class.
#include <algorithm>
#include <chrono>
#include <csignal>
#include <fstream>
#include <iostream>
#include <map>

#include "bench/bench_point.h"
#include "bench/bench_reachable.h"
#include "bench/job_deadline.h"
#include "bench/worst_keyframe.h"
#include "app/optimize_job.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "report/plot.h"

namespace kf {

namespace {

std::string load_average() {
  std::ifstream in("/proc/loadavg");
  std::string a, b, c;
  in >> a >> b >> c;
  return a + " " + b + " " + c;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// "smoke": the first scene of every class and the first multi-keyframe drop and throw.
bool wanted(const ReachableSweepOptions& o, const std::string& name) {
  if (o.scenes.empty()) return true;
  for (const std::string& s : o.scenes) {
    if (s == name) return true;
    if (s == "smoke" && (name.size() > 2 && name.compare(name.size() - 2, 2, "-0") == 0)) return true;
    if (s == "smoke" && (name == "drop-collider-1" || name == "throw-1")) return true;
  }
  return false;
}

extern "C" void ignore_signal(int) {}

struct ClassTally {
  int scenes = 0, passed = 0;
  std::vector<double> evaluations, seconds, cpu_seconds;
};

// One scene's optimize job, cut at the pass CPU time (or the wall limit), and its report (copied to out/reports/).
struct SceneRun {
  OptimizeOutcome outcome;
  nlohmann::json report;
  bool cut = false;
  double seconds = 0, cpu_seconds = 0;
  std::string load;  // the 1-minute load average as the job started
};

SceneRun run_scene(const ReachableSweepOptions& o, const std::string& name, const std::filesystem::path& file,
                   const std::filesystem::path& out) {
  OptimizeOptions opt;
  opt.out = (o.runs_dir / name).string();
  opt.quiet = true;
  if (o.max_seconds > 0) opt.max_seconds = o.max_seconds;
  if (o.stop_when_reached) opt.stop_when_reached = 1;
  SceneRun run;
  run.load = load_average();
  std::cerr << "bench reachable: " << name << " (load " << run.load << ")" << std::endl;
  run.load = run.load.substr(0, run.load.find(' '));
  const double cpu_start = process_cpu_seconds();
  const auto start = std::chrono::steady_clock::now();
  {
    JobDeadline deadline(o.pass_seconds, o.wall_seconds);
    run.outcome = optimize_job(file, opt);
    run.cut = deadline.fired();
  }
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  run.cpu_seconds = process_cpu_seconds() - cpu_start;
  // A job cut before its first evaluation writes no run directory (one cut in its throw search reports its best throw).
  if (!std::filesystem::exists(run.outcome.dir / "report.json")) return run;
  std::ifstream in(run.outcome.dir / "report.json");
  run.report = nlohmann::json::parse(in);
  write_file_atomic(out / "reports" / (name + ".json"), run.report.dump(1) + "\n");
  return run;
}

// reachable_classes.csv (pass rate, median evaluations, median and worst seconds a class) and its plot.
void write_class_table(const std::map<std::string, ClassTally>& tally, int rows, const std::filesystem::path& out) {
  CsvTable classes({"class", "scenes", "passed", "pass_rate", "median_evaluations", "median_seconds", "worst_seconds",
                    "median_cpu_seconds", "worst_cpu_seconds"});
  for (const auto& [kind, c] : tally)
    classes.add({kind, std::to_string(c.scenes), std::to_string(c.passed), fmt(double(c.passed) / c.scenes),
                 fmt(median(c.evaluations)), fmt(median(c.seconds)),
                 fmt(*std::max_element(c.seconds.begin(), c.seconds.end())), fmt(median(c.cpu_seconds)),
                 fmt(*std::max_element(c.cpu_seconds.begin(), c.cpu_seconds.end()))});
  classes.write(out / "reachable_classes.csv");
  if (rows > 0)
    bar_plot_csv(out / "reachable_classes.csv", out / "reachable.png", "pass rate by class (1: every scene passed)",
                 {classes.col("class")}, {classes.col("pass_rate")}, false);
  std::cout << classes.excerpt(100) << std::endl;
}

// One scene's figures added to its class and to the whole suite's.
void count_scene(ClassTally& c, bool pass, int evaluations, const SceneRun& run, std::vector<double>& all_seconds,
                 std::vector<double>& all_cpu) {
  ++c.scenes;
  c.passed += pass;
  c.evaluations.push_back(evaluations);
  c.seconds.push_back(run.seconds);
  c.cpu_seconds.push_back(run.cpu_seconds);
  all_seconds.push_back(run.seconds);
  all_cpu.push_back(run.cpu_seconds);
}

// The suite's totals into the summary and load.txt, and one line to the terminal.
void finish_summary(nlohmann::json& summary, int passed, int rows, const std::vector<double>& all_seconds,
                    const std::vector<double>& all_cpu, const std::filesystem::path& out) {
  summary["load_after"] = load_average();
  summary["passed"] = passed;
  summary["scenes"] = rows;
  summary["median_seconds"] = median(all_seconds);
  summary["median_cpu_seconds"] = median(all_cpu);
  summary["worst_seconds"] = all_seconds.empty() ? 0.0 : *std::max_element(all_seconds.begin(), all_seconds.end());
  summary["worst_cpu_seconds"] = all_cpu.empty() ? 0.0 : *std::max_element(all_cpu.begin(), all_cpu.end());
  write_file_atomic(out / "load.txt", "load average (1, 5, 15 min) before: " + summary["load_before"].get<std::string>() +
                                          "\nafter: " + summary["load_after"].get<std::string>() + "\n");
  std::cout << "reachable.csv: " << passed << " of " << rows << " scenes pass; median " << fmt(median(all_seconds))
            << " s (" << fmt(median(all_cpu)) << " CPU s), worst " << summary["worst_seconds"].get<double>() << " s"
            << std::endl;
}

// A row of reachable.csv: the scene's own columns (name to particles), then what its run measured.
std::vector<std::string> scene_columns(const std::string& name, const ReachableScene& r,
                                       const std::vector<std::string>& measured) {
  const nlohmann::json& s = r.scene;
  std::vector<std::string> row = {
      name, r.kind, std::to_string(r.keyframes), r.friction ? "yes" : "no", r.thrown ? "yes" : "no",
      r.character ? "yes" : "no", s.at("controls").at("kind").get<std::string>(), std::to_string(r.particles)};
  row.insert(row.end(), measured.begin(), measured.end());
  return row;
}

// A scene drawn well conditioned: its redraws and measure into redraws.csv (written after each).
void add_redraws(CsvTable& redraws, const ReachableScene& r, const std::filesystem::path& out) {
  redraws.add({r.name, r.kind, std::to_string(r.redraws), r.conditioning < 0 ? "" : fmt(r.conditioning)});
  redraws.write(out / "redraws.csv");
}

}  // namespace

void check_reachable_options(const ReachableSweepOptions& o) {
  const auto suite = reachable_suite(o);  // its classes and count; the names are not a filter there
  for (const std::string& s : o.scenes)
    if (s != "smoke" && std::none_of(suite.begin(), suite.end(), [&](const auto& n) { return n.first == s; }))
      throw InputError("--reachable-scenes: no scene \"" + s + "\" among the " + std::to_string(suite.size()) +
                       " the generator draws (seed " + std::to_string(o.seed) + "; names are CLASS-INDEX, e.g. " +
                       (suite.empty() ? std::string("throw-3") : suite.front().first) + ")");
}

nlohmann::json bench_reachable(const ReachableSweepOptions& o, const std::filesystem::path& out) {
  CsvTable t({"scene", "class", "keyframes", "friction", "thrown", "character", "controls", "particles", "keyframe",
              "miss_before", "miss_after", "evaluations", "seconds", "cpu_seconds", "load", "outcome", "pass"});
  if (!o.plot_classes.empty()) {
    std::filesystem::path png = o.plot_classes;
    bar_plot_csv(o.plot_classes, png.replace_extension(".png"), "pass rate by class (1: every scene passed)", {1}, {4},
                 false);
    return {{"plot", png.string()}};
  }
  check_reachable_options(o);
  nlohmann::json summary = {{"seed", o.seed}, {"load_before", load_average()}};
  std::map<std::string, ClassTally> tally;
  ensure_directory(o.scene_dir);
  std::signal(SIGHUP, ignore_signal);
  ensure_directory(out / "reports");
  int passed = 0, rows = 0;
  std::vector<double> all_seconds, all_cpu;
  CsvTable redraws({"scene", "class", "redraws", "conditioning"});
  for (const auto& [name, kind] : reachable_suite(o)) {
    if (!wanted(o, name)) continue;
    const int index = std::stoi(name.substr(name.rfind('-') + 1));
    const std::filesystem::path file = o.scene_dir / (name + ".json");
    const ReachableScene r = generate_reachable(kind, o.seed, index, false, o.scene_dir, o.well_conditioned);
    write_file_atomic(file, r.scene.dump(1) + "\n");
    if (o.well_conditioned) add_redraws(redraws, r, out);
    if (o.generate_only) continue;
    const SceneRun run = run_scene(o, name, file, out);
    const nlohmann::json& report = run.report;
    const bool cut = run.cut;
    const double seconds = run.seconds;
    if (report.is_null()) {  // cut before its first evaluation: a failure with nothing measured
      ++rows;
      count_scene(tally[kind], false, 0, run, all_seconds, all_cpu);
      t.add(scene_columns(name, r, {"", "", "", "0", fmt(seconds), fmt(run.cpu_seconds), run.load,
                                    "cut before its first evaluation", "no"}));
      t.write(out / "reachable.csv");
      continue;
    }
    const nlohmann::json* worst = worst_judged_keyframe(report);
    if (!worst) continue;
    const bool pass = !cut && report.at("diagnosis").at("reached").get<bool>() && run.cpu_seconds <= o.pass_seconds;
    const int evaluations = report.at("evaluations").get<int>();
    passed += pass;
    ++rows;
    count_scene(tally[kind], pass, evaluations, run, all_seconds, all_cpu);
    t.add(scene_columns(name, r,
                        {worst->at("name").get<std::string>(), fmt(worst->at("miss_before").get<double>()),
                         fmt(worst->at("miss_after").get<double>()), std::to_string(evaluations), fmt(seconds),
                         fmt(run.cpu_seconds), run.load,
                         cut ? "cut" : report.at("diagnosis").at("outcome").get<std::string>(), pass ? "yes" : "no"}));
    t.write(out / "reachable.csv");  // after every scene: a cut-off run keeps what it measured
    summary["diagnoses"][name] = run.outcome.diagnosis;
  }
  if (o.generate_only) return summary;
  write_class_table(tally, rows, out);
  finish_summary(summary, passed, rows, all_seconds, all_cpu, out);
  return summary;
}

}  // namespace kf
