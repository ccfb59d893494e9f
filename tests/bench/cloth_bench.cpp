// Cloth forward and adjoint steps at the paper's resolutions (16^2 .. 50^2; ring toss is 50x50).
// Each benchmark iteration is a 10-step segment (forward: simulate; backward: the adjoint pass over it),
// as in an optimisation, so warm-started PCG is measured as it is used. Time is per step.
// Counter cg = PCG iterations per step.
#include <benchmark/benchmark.h>

#include "adjoint/rollout.h"
#include "scene/scene.h"
#include "sim/cloth/cloth_system.h"

namespace {

constexpr int kSteps = 10;

kf::ClothSpec bench_spec(int n) {
  const std::string j = R"({"cloth": {"nx": )" + std::to_string(n) + R"(, "ny": )" + std::to_string(n) +
                        R"(, "pins": "top_corners", "colliders": [{"type": "sphere", "center": [0.5, 0.3, 0.3],
                        "radius": 0.3}]}})";
  return *kf::parse_scene(j, "bench.json").cloth;
}

struct EndCost : kf::StateCost {
  bool active(int n) const override { return n == kSteps; }
  double eval(int, const kf::VecX& x, const kf::VecX&, kf::VecX& gx, kf::VecX&) const override {
    gx += x;
    return 0.5 * x.squaredNorm();
  }
};

// A cloth 20 steps into its fall (springs stretched and compressed, some particles on the sphere).
struct Warm {
  kf::ClothSystem sys;
  kf::VecX x, v;
  std::vector<kf::VecX> U;
  kf::Rollout r;
  explicit Warm(int n) : sys(bench_spec(n), 1.0 / 60) {
    sys.initial_state(x, v);
    kf::Rollout start;
    simulate(sys, x, v, std::vector<kf::VecX>(20, kf::VecX::Zero(x.size())), start);
    x = start.x.back();
    v = start.v.back();
    U.assign(kSteps, kf::VecX::Zero(x.size()));
    simulate(sys, x, v, U, r);
  }
};

void BM_ClothStep(benchmark::State& state) {
  Warm w(int(state.range(0)));
  double cg = 0;
  for (auto _ : state) {
    for (int n = 0; n < kSteps; ++n) {
      w.sys.step(n, w.r.x[n], w.r.v[n], w.U[n], w.r.x[n + 1], w.r.v[n + 1]);
      cg += w.sys.last_cg_iterations();
    }
  }
  state.counters["cg"] = benchmark::Counter(cg / kSteps, benchmark::Counter::kAvgIterations);
  state.counters["ms_per_step"] =
      benchmark::Counter(double(kSteps) * state.iterations(), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_ClothStep)->Arg(16)->Arg(32)->Arg(50)->Unit(benchmark::kMillisecond);

void BM_ClothStepAdjoint(benchmark::State& state) {
  Warm w(int(state.range(0)));
  const int dof = int(w.x.size());
  kf::VecX xhat = kf::VecX::Constant(dof, 0.1), vhat = kf::VecX::Constant(dof, 0.01), xp, vp, uhat;
  double cg = 0;
  for (auto _ : state) {
    for (int n = kSteps - 1; n >= 0; --n) {
      w.sys.step_adjoint(n, w.r.x[n], w.r.v[n], w.U[n], xhat, vhat, xp, vp, uhat);
      cg += w.sys.last_adjoint_cg_iterations();
      xhat.swap(xp);
      vhat.swap(vp);
      xhat *= 1e-3 / (1e-300 + xhat.norm());  // keep the adjoint bounded over repetitions
      vhat *= 1e-3 / (1e-300 + vhat.norm());
    }
  }
  state.counters["cg"] = benchmark::Counter(cg / kSteps, benchmark::Counter::kAvgIterations);
  state.counters["ms_per_step"] =
      benchmark::Counter(double(kSteps) * state.iterations(), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_ClothStepAdjoint)->Arg(16)->Arg(32)->Arg(50)->Unit(benchmark::kMillisecond);

// The part of a backward step that storing A per step would save.
void BM_ClothAssemble(benchmark::State& state) {
  Warm w(int(state.range(0)));
  for (auto _ : state) w.sys.assemble(0, w.x, w.v);
}
BENCHMARK(BM_ClothAssemble)->Arg(16)->Arg(32)->Arg(50)->Unit(benchmark::kMillisecond);

}  // namespace
