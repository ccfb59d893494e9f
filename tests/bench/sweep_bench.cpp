// Cost of adjoint checkpointing and of machinery a scene does not ask for.
//  BM_ClothGradient/every: one forward + adjoint pass of a 16x16 cloth over 1,000 steps with checkpoints
//    every `every` steps (0 = all states stored); counter state_kb = states held.
//  BM_ClothStepColliders/c: one cloth step with c colliders placed where nothing touches them
//    (0 = none built): what a cloth without colliders saves.
//  BM_FlockStep: a flock step for comparison; a flock builds no cloth matrices at all.
#include <benchmark/benchmark.h>

#include "opt/problem.h"
#include "scene/scene.h"
#include "sim/make_system.h"

namespace {

kf::Scene cloth_scene(int every, const std::string& colliders, int frames) {
  const std::string text = R"({
    "time": {"fps": 30, "substeps": 40, "frames": )" + std::to_string(frames) + R"(},
    "cloth": {"nx": 16, "ny": 16, "pins": "top_corners", "colliders": [)" + colliders + R"(]},
    "objectives": [{"type": "center_of_mass", "frame": )" + std::to_string(frames) + R"(, "target": [0.5, 0.3, 0.3]}],
    "controls": {"kind": "per_frame", "alpha": 0.001},
    "optimizer": {"checkpoint_every": )" + std::to_string(every) + R"(}
  })";
  return kf::parse_scene(text, "sweep.json");
}

void BM_ClothGradient(benchmark::State& state) {
  const kf::Scene scene = cloth_scene(int(state.range(0)), "", 25);  // 1,000 steps
  auto sys = kf::make_system(scene);
  kf::Problem problem(scene, scene.time, *sys);
  kf::VecX z = problem.initial_guess(), g(problem.size());
  for (auto _ : state) benchmark::DoNotOptimize(problem.evaluate(z, &g));
  state.counters["state_kb"] = double(problem.rollout().stored_bytes()) / 1024;
}
BENCHMARK(BM_ClothGradient)->Arg(0)->Arg(10)->Arg(50)->Arg(200)->Unit(benchmark::kMillisecond);

void BM_ClothStepColliders(benchmark::State& state) {
  std::string colliders;
  const char* far[] = {R"({"type": "ground", "center": [0, -50, 0]})",
                       R"({"type": "sphere", "center": [0, -50, 0], "radius": 1})",
                       R"({"type": "torus", "center": [0, -50, 0], "radius": 1})"};
  for (int c = 0; c < state.range(0); ++c) colliders += std::string(c ? ", " : "") + far[c % 3];
  const kf::Scene scene = cloth_scene(0, colliders, 1);
  auto sys = kf::make_system(scene);
  kf::VecX x, v, x1(sys->dof()), v1(sys->dof()), u = kf::VecX::Zero(sys->dof());
  sys->initial_state(x, v);
  int n = 0;
  for (auto _ : state) benchmark::DoNotOptimize(sys->step(n++ % 40, x, v, u, x1, v1));
}
BENCHMARK(BM_ClothStepColliders)->Arg(0)->Arg(1)->Arg(3)->Unit(benchmark::kMicrosecond);

void BM_FlockStep(benchmark::State& state) {
  const kf::Scene scene = kf::parse_scene(R"({"flock": {"agents": 256, "spawn": {"radius": 12}}})", "f.json");
  auto sys = kf::make_system(scene);
  kf::VecX x, v, x1(sys->dof()), v1(sys->dof()), u = kf::VecX::Zero(sys->dof());
  sys->initial_state(x, v);
  int n = 0;
  for (auto _ : state) benchmark::DoNotOptimize(sys->step(n++ % 100, x, v, u, x1, v1));
}
BENCHMARK(BM_FlockStep)->Unit(benchmark::kMicrosecond);

}  // namespace
