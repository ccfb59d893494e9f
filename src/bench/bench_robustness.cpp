// Robustness sweep: scenes written the way a new user writes them (scenes/robustness/), each optimised with
// `keyframe optimize`'s own job at its default settings and judged by its keyframes (opt/diagnosis.h).
#include <algorithm>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>

#include "bench/bench_point.h"
#include "bench/bench_sweeps.h"
#include "bench/job_deadline.h"
#include "bench/worst_keyframe.h"
#include "app/optimize_job.h"
#include "report/plot.h"
#include "core/atomic_file.h"
#include "core/error.h"

namespace kf {

namespace {

// The scene names in `dir` (every *.json, sorted) when none are given.
std::vector<std::string> suite_scenes(const RobustnessSweepOptions& o) {
  if (!o.scenes.empty()) return o.scenes;
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(o.scene_dir))
    if (e.path().extension() == ".json") names.push_back(e.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

// What the optimiser did, as the table names it: the report's strategy when it states one, else the
// control kind of each stage.
std::string strategy_of(const nlohmann::json& report) {
  if (report.contains("strategy") && report.at("strategy").is_string()) return report.at("strategy").get<std::string>();
  std::string s;
  for (const auto& st : report.at("stage_results")) s += (s.empty() ? "" : " then ") + st.at("kind").get<std::string>();
  return "L-BFGS " + s;
}

extern "C" void ignore_hangup(int) {}

struct SuiteJob {
  OptimizeOutcome outcome;
  bool cut = false;  // the job's CPU or wall deadline fired
  double seconds = 0, cpu_seconds = 0;
};

// Optimises one scene under the suite's deadlines; nothing (and a "skipped" line in the summary) when the
// scene is refused as input.
std::optional<SuiteJob> run_suite_job(const RobustnessSweepOptions& o, const std::string& name,
                                      const std::filesystem::path& file, nlohmann::json& summary) {
  OptimizeOptions opt;
  opt.out = (o.runs_dir / name).string();
  opt.quiet = true;
  opt.max_evaluations = o.max_evaluations;
  if (o.max_seconds > 0) opt.max_seconds = o.max_seconds;
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = process_cpu_seconds();
  SuiteJob job;
  try {
    JobDeadline deadline(o.pass_seconds, o.wall_seconds);
    job.outcome = optimize_job(file, opt);
    job.cut = deadline.fired();
  } catch (const InputError& e) {
    std::cerr << "bench robustness: skipping " << name << ": " << e.what() << std::endl;
    summary["skipped"].push_back(name + ": " + e.what());
    return std::nullopt;
  }
  job.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  job.cpu_seconds = process_cpu_seconds() - cpu_start;
  return job;
}

}  // namespace

nlohmann::json bench_robustness(const RobustnessSweepOptions& o, const std::filesystem::path& out) {
  CsvTable t({"scene", "system", "strategy", "keyframe", "error_before", "error_after", "tolerance", "miss_before",
              "miss_after", "evaluations", "seconds", "cpu_seconds", "outcome", "pass"});
  nlohmann::json summary;
  std::signal(SIGHUP, ignore_hangup);  // a cut (bench/job_deadline.h) that lands as a job ends
  int passed = 0, rows = 0;
  for (const std::string& name : suite_scenes(o)) {
    const std::filesystem::path file = o.scene_dir / (name + ".json");
    std::cerr << "bench robustness: " << name << std::endl;
    const std::optional<SuiteJob> job = run_suite_job(o, name, file, summary);
    if (!job) continue;
    const OptimizeOutcome& outcome = job->outcome;
    const bool cut = job->cut;
    const double seconds = job->seconds, cpu_seconds = job->cpu_seconds;
    if (!std::filesystem::exists(outcome.dir / "report.json")) {  // cut before its first evaluation
      ++rows;
      t.add({name, "", "", "", "", "", "", "", "", "0", fmt(seconds), fmt(cpu_seconds), "cut before its first evaluation",
             "no"});
      t.write(out / "robustness.csv");
      continue;
    }
    std::ifstream in(outcome.dir / "report.json");
    const nlohmann::json report = nlohmann::json::parse(in);
    ensure_directory(out / "reports");
    write_file_atomic(out / "reports" / (name + ".json"), report.dump(1) + "\n");
    // The scene's worst keyframe (by its miss after the optimisation) stands for it in the table.
    const nlohmann::json* worst = worst_judged_keyframe(report);
    if (!worst) continue;
    const bool pass = !cut && report.at("diagnosis").at("reached").get<bool>() && cpu_seconds <= o.pass_seconds;
    passed += pass;
    ++rows;
    const std::string system = report.at("system").get<std::string>();
    auto text = [&](const char* key) { return worst->at(key).get<std::string>(); };
    t.add({name, system.substr(0, system.find_first_of(": ")), strategy_of(report), text("name"), text("error_before"),
           text("error_after"), text("tolerance"), fmt(worst->at("miss_before").get<double>()),
           fmt(worst->at("miss_after").get<double>()), std::to_string(report.at("evaluations").get<int>()),
           fmt(seconds), fmt(cpu_seconds), cut ? "cut" : report.at("diagnosis").at("outcome").get<std::string>(),
           pass ? "yes" : "no"});
    summary["diagnoses"][name] = outcome.diagnosis;
    t.write(out / "robustness.csv");  // after every scene: a run stopped early keeps what it measured
  }
  const auto csv = out / "robustness.csv";
  t.write(csv);
  if (rows > 0)
    bar_plot_csv(csv, out / "robustness.png",
                 "worst keyframe error over its tolerance, uncontrolled and optimised (1: met)", {t.col("scene")},
                 {t.col("miss_before"), t.col("miss_after")});
  summary["passed"] = passed;
  summary["scenes"] = rows;
  std::cout << "robustness.csv: " << passed << " of " << rows << " scenes pass\n" << t.excerpt(100) << std::endl;
  return summary;
}

}  // namespace kf
