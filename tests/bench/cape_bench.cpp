// The cape blend (paper figure 6) end to end: the whole `keyframe optimize scenes/cape-blend.json` (every
// stage of its schedule, one iteration: minutes) into a temporary run directory, and one gradient
// evaluation (forward + adjoint) at the scene's final step. The blend reads the runs out/cape-a and
// out/cape-b (make them first with `keyframe run scenes/cape-a.json` and `scenes/cape-b.json`); scenes are
// read from $KEYFRAME_SOURCE_DIR/scenes (default: ./scenes, so run from the repository root).
// Counters: evaluations, end_error_percent (end-state RMS position error over the cape length), wall_s.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "app/optimize_job.h"
#include "opt/problem.h"
#include "scene/scene.h"
#include "sim/make_system.h"

namespace {

std::filesystem::path blend_scene() {
  const char* root = std::getenv("KEYFRAME_SOURCE_DIR");
  return std::filesystem::path(root ? root : ".") / "scenes/cape-blend.json";
}

void BM_CapeBlendOptimisation(benchmark::State& state) {
  const auto out = std::filesystem::temp_directory_path() / ("keyframe_cape_bench_" + std::to_string(::getpid()));
  for (auto _ : state) {
    kf::OptimizeOptions o;
    o.out = out.string();
    o.quiet = true;
    kf::optimize_job(blend_scene(), o);
  }
  std::ifstream in(out / "report.json");
  const nlohmann::json r = nlohmann::json::parse(in);
  state.counters["evaluations"] = r["evaluations"].get<double>();
  state.counters["wall_s"] = r["wall_seconds"].get<double>();
  state.counters["end_error_percent"] = r["cape_end_state"]["controlled"]["rms_position_error_percent"].get<double>();
  std::filesystem::remove_all(out);
}
BENCHMARK(BM_CapeBlendOptimisation)->Iterations(1)->Unit(benchmark::kSecond);

void BM_CapeBlendGradient(benchmark::State& state) {
  const kf::Scene scene = kf::load_scene(blend_scene());
  auto sys = kf::make_system(scene);
  kf::Problem problem(scene, scene.time, *sys);
  const kf::VecX z = problem.initial_guess();
  kf::VecX g;
  for (auto _ : state) benchmark::DoNotOptimize(problem.evaluate(z, &g));
}
BENCHMARK(BM_CapeBlendGradient)->Unit(benchmark::kMillisecond);

}  // namespace
