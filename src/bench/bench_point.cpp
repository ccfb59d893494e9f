#include "bench/bench_point.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <sstream>

#include "core/atomic_file.h"
#include "opt/gradcheck.h"
#include "opt/optimizer.h"
#include "opt/term_breakdown.h"
#include "sim/make_system.h"

namespace kf {

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

BenchPoint measure_point(const Scene& scene, const BenchPointOptions& o) {
  BenchPoint p;
  auto sys = make_system(scene);
  Problem problem(scene, scene.time, *sys);
  p.steps = scene.time.steps();
  p.control_variables = problem.size();
  const VecX z0 = problem.initial_guess();
  VecX g(problem.size());
  p.forward_s = p.gradient_s = 1e300;
  for (int r = 0; r < std::max(1, o.repeats); ++r) {
    auto t0 = std::chrono::steady_clock::now();
    problem.evaluate(z0, nullptr);
    p.forward_s = std::min(p.forward_s, seconds_since(t0));
    t0 = std::chrono::steady_clock::now();
    problem.evaluate(z0, &g);
    p.gradient_s = std::min(p.gradient_s, seconds_since(t0));
  }
  p.diverged = problem.last_diverged();
  p.keyframe_initial = keyframe_terms_sum(problem);
  if (o.gradcheck_samples > 0 && !p.diverged) {
    const GradcheckResult c = gradcheck(problem, z0, {.samples = o.gradcheck_samples, .eps = o.gradcheck_eps});
    p.gradchecked = true;
    p.grad_cosine = c.cosine;
    p.grad_rel_error = c.rel_error_norm;
  }
  p.keyframe_final = p.keyframe_initial;
  if (o.optimize_evaluations > 0 && !p.diverged) {
    OptimizerSpec spec = scene.optimizer;
    spec.max_evaluations = o.optimize_evaluations;
    spec.max_seconds = o.optimize_seconds;
    const auto t0 = std::chrono::steady_clock::now();
    const OptimizeResult r = minimize(problem, spec, z0);
    p.optimize_s = seconds_since(t0);
    p.evaluations = r.evaluations;
    problem.evaluate(r.z, nullptr);
    p.keyframe_final = keyframe_terms_sum(problem);
  }
  return p;
}

int CsvTable::col(const std::string& name) const {
  auto it = std::find(columns_.begin(), columns_.end(), name);
  return it == columns_.end() ? 0 : int(it - columns_.begin()) + 1;
}

void CsvTable::write(const std::filesystem::path& path) const {
  write_file_atomic(path, excerpt(int(rows_.size())));
}

std::string CsvTable::excerpt(int max_rows) const {
  std::ostringstream os;
  for (size_t c = 0; c < columns_.size(); ++c) os << (c ? "," : "") << columns_[c];
  os << "\n";
  for (int r = 0; r < std::min<int>(max_rows, int(rows_.size())); ++r) {
    for (size_t c = 0; c < rows_[r].size(); ++c) os << (c ? "," : "") << rows_[r][c];
    os << "\n";
  }
  return os.str();
}

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::vector<std::string> bench_point_columns() {
  return {"steps",          "control_variables", "forward_s",        "gradient_s",     "grad_cosine",
          "grad_rel_error", "keyframe_initial",  "keyframe_final",   "optimize_s",     "evaluations",
          "diverged"};
}

std::vector<std::string> bench_point_row(const BenchPoint& p) {
  return {std::to_string(p.steps),  std::to_string(p.control_variables), fmt(p.forward_s),
          fmt(p.gradient_s),        p.gradchecked ? fmt(p.grad_cosine) : "",
          p.gradchecked ? fmt(p.grad_rel_error) : "",
          fmt(p.keyframe_initial),  fmt(p.keyframe_final),               fmt(p.optimize_s),
          std::to_string(p.evaluations), p.diverged ? "1" : "0"};
}

}  // namespace kf
