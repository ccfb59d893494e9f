// Cloth step and adjoint step at the paper's resolutions (16^2 .. 50^2, ring toss is 50x50).
// Counters: cg = PCG iterations per step of the measured pass.
#include <benchmark/benchmark.h>

#include "scene/scene.h"
#include "sim/cloth/cloth_system.h"

namespace {

kf::ClothSpec bench_spec(int n) {
  const std::string j = R"({"cloth": {"nx": )" + std::to_string(n) + R"(, "ny": )" + std::to_string(n) +
                        R"(, "pins": "top_corners", "colliders": [{"type": "sphere", "center": [0.5, 0.3, 0.3],
                        "radius": 0.3}]}})";
  return *kf::parse_scene(j, "bench.json").cloth;
}

// A cloth a few steps into its fall, so springs are stretched, compressed and some particles in contact.
struct Warm {
  kf::ClothSystem sys;
  kf::VecX x, v, u, x1, v1;
  explicit Warm(int n) : sys(bench_spec(n), 1.0 / 60) {
    sys.initial_state(x, v);
    u.setZero(x.size());
    for (int k = 0; k < 20; ++k) {
      sys.step(k, x, v, u, x1, v1);
      x.swap(x1);
      v.swap(v1);
    }
  }
};

void BM_ClothStep(benchmark::State& state) {
  Warm w(int(state.range(0)));
  double cg = 0;
  for (auto _ : state) {
    w.sys.step(20, w.x, w.v, w.u, w.x1, w.v1);
    cg += w.sys.last_cg_iterations();
  }
  state.counters["cg"] = benchmark::Counter(cg, benchmark::Counter::kAvgIterations);
}
BENCHMARK(BM_ClothStep)->Arg(16)->Arg(32)->Arg(50)->Unit(benchmark::kMillisecond);

void BM_ClothStepAdjoint(benchmark::State& state) {
  Warm w(int(state.range(0)));
  const kf::VecX xhat1 = kf::VecX::Constant(w.x.size(), 0.1), vhat1 = kf::VecX::Constant(w.x.size(), 0.01);
  kf::VecX xhat, vhat, uhat;
  double cg = 0;
  for (auto _ : state) {
    w.sys.step_adjoint(20, w.x, w.v, w.u, xhat1, vhat1, xhat, vhat, uhat);
    cg += w.sys.last_adjoint_cg_iterations();
  }
  state.counters["cg"] = benchmark::Counter(cg, benchmark::Counter::kAvgIterations);
}
BENCHMARK(BM_ClothStepAdjoint)->Arg(16)->Arg(32)->Arg(50)->Unit(benchmark::kMillisecond);

// The part of a backward step that storing A per step would save.
void BM_ClothAssemble(benchmark::State& state) {
  Warm w(int(state.range(0)));
  for (auto _ : state) w.sys.assemble(20, w.x, w.v);
}
BENCHMARK(BM_ClothAssemble)->Arg(16)->Arg(32)->Arg(50)->Unit(benchmark::kMillisecond);

// The gradient test's cloth (6x6), to keep that test's cost in view.
void BM_ClothStepTiny(benchmark::State& state) {
  Warm w(6);
  for (auto _ : state) w.sys.step(20, w.x, w.v, w.u, w.x1, w.v1);
  state.counters["cg"] = w.sys.last_cg_iterations();
}
BENCHMARK(BM_ClothStepTiny)->Unit(benchmark::kMicrosecond);

}  // namespace
