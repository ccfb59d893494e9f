#pragma once
// The crowd sweep of `keyframe bench --only flock`: a figure scene scaled to more agents at its density and
// optimised in a fresh process per point, so each point's peak memory is its own.
#include <filesystem>
#include <vector>

#include <nlohmann/json.hpp>

namespace kf {

struct CrowdSweepOptions {
  std::filesystem::path scene = "scenes/square.json";  // a flock scene with shape keyframes
  std::vector<int> agents{200, 1000, 3000, 10000, 30000, 100000};
  int evaluations = 60;
  // Sizes run again with a memory budget of budget_gb (GB), which switches checkpointing on.
  std::vector<int> budget_agents{10000};
  double budget_gb = 0.7;
  // Keep the scene's coverage terms (shapes filled, not only entered); the results then go to
  // flock_crowd_coverage.csv and its plots, the runs to <out>/crowd/square-N-coverage*.
  bool coverage = false;
  // Each run stops at its first evaluation that meets both shapes (optimizer.stop_when_reached); the runs
  // are then named square-N-reached.
  bool stop_when_reached = false;
  // Every keyframe's weight scaled by sqrt(agents / base agents) as well: the distances to travel grow with
  // the shapes, so the effort of the last step into a shape grows with them while a shape's penalty for a
  // given miss does not; the runs are then named square-N-weighted, the results flock_crowd_weighted.*.
  bool scale_weights = false;
};

// Writes <out>/flock_crowd.csv, flock_crowd_time.png, flock_crowd_memory.png (flock_crowd_coverage.* with
// coverage kept, *_weighted.* with the weights scaled) and the runs under <out>/crowd/ (`self` is this
// executable). Points run in the order given, budgeted ones after the others.
nlohmann::json bench_crowd(const CrowdSweepOptions& o, const std::filesystem::path& out,
                           const std::filesystem::path& self);

}  // namespace kf
