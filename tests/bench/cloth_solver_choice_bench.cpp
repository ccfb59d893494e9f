// The cloth step's linear solve, PCG (IC(0), the scene default 1e-8) against the sparse direct solve, on a
// sheet 20 steps into its fall onto a sphere (in contact, springs stretched and compressed), from the cape's
// sizes (14^2, 20^2, 24^2) to where the direct solve stops paying (32^2, 50^2). Each iteration is what an
// evaluation does per step: a 10-step forward segment and the adjoint pass back over it. CPU time is per
// iteration; ms_per_step is per forward + adjoint step. Arguments: n, solver (0: PCG, 1: direct).
#include <benchmark/benchmark.h>

#include "adjoint/rollout.h"
#include "scene/scene.h"
#include "sim/cloth/cloth_system.h"

namespace {

constexpr int kSteps = 10;

kf::ClothSpec solver_spec(int n, bool direct) {
  const std::string j = R"({"cloth": {"nx": )" + std::to_string(n) + R"(, "ny": )" + std::to_string(n) +
                        R"(, "pins": "top_corners", "solver": ")" + (direct ? "direct" : "pcg") +
                        R"(", "colliders": [{"type": "sphere", "center": [0.5, 0.3, 0.3], "radius": 0.3}]}})";
  return *kf::parse_scene(j, "solver_choice_bench.json").cloth;
}

void BM_ClothForwardAdjointStep(benchmark::State& state) {
  const int n = int(state.range(0));
  kf::ClothSystem sys(solver_spec(n, state.range(1) == 1), 1.0 / 60);
  kf::VecX x, v;
  sys.initial_state(x, v);
  kf::Rollout start, r;
  simulate(sys, x, v, std::vector<kf::VecX>(20, kf::VecX::Zero(x.size())), start);
  const std::vector<kf::VecX> U(kSteps, kf::VecX::Zero(x.size()));
  simulate(sys, start.x.back(), start.v.back(), U, r);
  const int dof = int(x.size());
  kf::VecX xhat, vhat, xp, vp, uhat;
  for (auto _ : state) {
    for (int k = 0; k < kSteps; ++k) sys.step(k, r.x[k], r.v[k], U[k], r.x[k + 1], r.v[k + 1]);
    xhat = kf::VecX::Constant(dof, 1e-3);
    vhat = kf::VecX::Constant(dof, 1e-4);
    for (int k = kSteps - 1; k >= 0; --k) {
      sys.step_adjoint(k, r.x[k], r.v[k], U[k], xhat, vhat, xp, vp, uhat);
      xhat.swap(xp);
      vhat.swap(vp);
    }
    benchmark::DoNotOptimize(xhat.data());
  }
  state.counters["particles"] = n * n;
  state.counters["ms_per_step"] =
      benchmark::Counter(double(kSteps) * state.iterations(), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_ClothForwardAdjointStep)
    ->ArgsProduct({{14, 20, 24, 32, 50}, {0, 1}})
    ->Unit(benchmark::kMillisecond);

}  // namespace
