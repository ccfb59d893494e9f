// The flock figures end to end: the full square + cross optimisation (scenes/square.json), and one
// gradient (forward rollout + adjoint pass) against one forward rollout of the same 200-agent scene.
#include <benchmark/benchmark.h>

#include <filesystem>

#include "opt/optimizer.h"
#include "opt/problem.h"
#include "scene/scene.h"
#include "sim/make_system.h"

namespace {

std::filesystem::path scene_path(const char* name) {
  return std::filesystem::path(__FILE__).parent_path().parent_path().parent_path() / "scenes" / name;
}

void BM_SquareCrossOptimisation(benchmark::State& state) {
  const kf::Scene scene = kf::load_scene(scene_path("square.json"));
  for (auto _ : state) {
    auto sys = kf::make_system(scene, scene.time.h());
    kf::Problem problem(scene, scene.time, *sys);
    const kf::OptimizeResult r = kf::minimize(problem, scene.optimizer, problem.initial_guess());
    state.counters["evaluations"] = r.evaluations;
    state.counters["phi"] = r.phi;
  }
}

struct SquareProblem {
  SquareProblem() : scene(kf::load_scene(scene_path("square.json"))), sys(kf::make_system(scene, scene.time.h())),
                    problem(scene, scene.time, *sys), z(problem.initial_guess()), g(problem.size()) {
    z.setConstant(0.2);  // a generic point: forces on, agents moving apart
    problem.evaluate(z, &g);  // first call sizes every buffer
  }
  kf::Scene scene;
  std::unique_ptr<kf::System> sys;
  kf::Problem problem;
  kf::VecX z, g;
};

void BM_Flock200Forward(benchmark::State& state) {
  SquareProblem s;
  for (auto _ : state) benchmark::DoNotOptimize(s.problem.evaluate(s.z, nullptr));
  state.counters["steps"] = s.scene.time.steps();
}

void BM_Flock200Gradient(benchmark::State& state) {
  SquareProblem s;
  for (auto _ : state) benchmark::DoNotOptimize(s.problem.evaluate(s.z, &s.g));
  state.counters["steps"] = s.scene.time.steps();
}

}  // namespace

BENCHMARK(BM_SquareCrossOptimisation)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK(BM_Flock200Forward)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Flock200Gradient)->Unit(benchmark::kMillisecond);
