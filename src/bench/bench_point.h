#pragma once
// One point of a `keyframe bench` sweep: time a scene's forward pass and gradient, check the gradient
// against finite differences, run a short optimisation; and the CSV table the sweeps write.
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "scene/scene.h"

namespace kf {

struct BenchPointOptions {
  int gradcheck_samples = 0;    // 0: no finite-difference check
  double gradcheck_eps = 1e-5;  // relative finite-difference step
  int optimize_evaluations = 0; // 0: no optimisation
  double optimize_seconds = 0;  // > 0: the optimisation also stops after this wall time
  int repeats = 1;              // timings are the fastest of this many runs
};

struct BenchPoint {
  int steps = 0, control_variables = 0;
  double forward_s = 0;             // one forward simulation (s, wall clock)
  double gradient_s = 0;            // one forward + adjoint pass (s)
  bool gradchecked = false;         // the two below were measured (the CSV leaves them empty otherwise)
  double grad_cosine = 0;           // adjoint vs central differences on the sample (1 = same direction)
  double grad_rel_error = 0;        // ‖adjoint − fd‖ / ‖fd‖ on the sample
  double keyframe_initial = 0;      // keyframe terms of φ (no effort) at the initial guess
  double keyframe_final = 0;        // the same after the short optimisation
  double optimize_s = 0;            // wall clock of the short optimisation
  int evaluations = 0;
  bool diverged = false;            // the initial forward pass diverged
};

// Measures one point; the scene's own optimiser settings other than the evaluation budget apply.
BenchPoint measure_point(const Scene& scene, const BenchPointOptions& options);

// A CSV table written whole at the end; numbers with 6 significant digits.
class CsvTable {
 public:
  explicit CsvTable(std::vector<std::string> columns) : columns_(std::move(columns)) {}
  void add(const std::vector<std::string>& row) { rows_.push_back(row); }
  // 1-based column number for gnuplot.
  int col(const std::string& name) const;
  void write(const std::filesystem::path& path) const;
  std::string excerpt(int max_rows = 20) const;

 private:
  std::vector<std::string> columns_;
  std::vector<std::vector<std::string>> rows_;
};

std::string fmt(double v);
// The columns of a BenchPoint, in CsvTable order after any sweep-specific ones.
std::vector<std::string> bench_point_columns();
std::vector<std::string> bench_point_row(const BenchPoint& p);

}  // namespace kf
