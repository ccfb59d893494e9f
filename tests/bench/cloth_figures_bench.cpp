// The cloth figures end to end: a full optimisation of scenes/arch.json and scenes/ring-toss.json (one
// iteration each: minutes, not microseconds), and one forward rollout against one adjoint pass of the
// 50x50 ring toss (the backward/forward ratio). Scenes are read from $KEYFRAME_SOURCE_DIR/scenes
// (default: ./scenes, so run from the repository root).
// Counters: evaluations, phi (final objective), cg = PCG iterations per forward step.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <string>

#include "adjoint/rollout.h"
#include "opt/optimizer.h"
#include "opt/problem.h"
#include "scene/scene.h"
#include "sim/cloth/cloth_system.h"
#include "sim/make_system.h"

namespace {

kf::Scene figure_scene(const std::string& name) {
  const char* root = std::getenv("KEYFRAME_SOURCE_DIR");
  return kf::load_scene(std::string(root ? root : ".") + "/scenes/" + name + ".json");
}

void optimise_scene(benchmark::State& state, const std::string& name, const std::string& preconditioner) {
  kf::Scene scene = figure_scene(name);
  scene.cloth->cg_preconditioner = kf::cg_preconditioner(preconditioner);
  for (auto _ : state) {
    auto sys = kf::make_system(scene);
    kf::Problem problem(scene, scene.time, *sys);
    const kf::OptimizeResult r = kf::minimize(problem, scene.optimizer, problem.initial_guess());
    state.counters["evaluations"] = r.evaluations;
    state.counters["phi"] = r.phi;
  }
}

void BM_ArchOptimisation(benchmark::State& state) { optimise_scene(state, "arch", "incomplete_cholesky"); }
BENCHMARK(BM_ArchOptimisation)->Iterations(1)->Unit(benchmark::kSecond);

void BM_RingTossOptimisation(benchmark::State& state) { optimise_scene(state, "ring-toss", "incomplete_cholesky"); }
BENCHMARK(BM_RingTossOptimisation)->Iterations(1)->Unit(benchmark::kSecond);

struct EndCost : kf::StateCost {
  int last;
  bool active(int n) const override { return n == last; }
  double eval(int, const kf::VecX& x, const kf::VecX&, kf::VecX& gx, kf::VecX&) const override {
    gx += x;
    return 0.5 * x.squaredNorm();
  }
};

// Forward rollout (arg 0) or adjoint pass (arg 1) of the ring toss at 50x50; range(1): 0 block Jacobi,
// 1 incomplete Cholesky.
void BM_RingTossPass(benchmark::State& state) {
  kf::Scene scene = figure_scene("ring-toss");
  scene.cloth->cg_preconditioner =
      state.range(1) ? kf::CgPreconditioner::kIncompleteCholesky : kf::CgPreconditioner::kBlockJacobi;
  kf::ClothSystem sys(*scene.cloth, scene.time.h());
  kf::VecX x0, v0;
  sys.initial_state(x0, v0);
  const int N = scene.time.steps();
  const std::vector<kf::VecX> U(N, kf::VecX::Zero(x0.size()));
  kf::Rollout r;
  kf::simulate(sys, x0, v0, U, r);
  EndCost cost;
  cost.last = N;
  kf::VecX dx0, dv0;
  std::vector<kf::VecX> dU;
  double cg = 0;
  for (auto _ : state) {
    if (state.range(0) == 0) {
      for (int n = 0; n < N; ++n) {
        sys.step(n, r.x[n], r.v[n], U[n], r.x[n + 1], r.v[n + 1]);
        cg += sys.last_cg_iterations();
      }
    } else {
      kf::backward(sys, r, U, cost, dU, dx0, dv0);
    }
  }
  state.counters["cg"] = benchmark::Counter(cg / N, benchmark::Counter::kAvgIterations);
  state.counters["ms_per_step"] =
      benchmark::Counter(double(N) * state.iterations(), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_RingTossPass)->ArgsProduct({{0, 1}, {0, 1}})->ArgNames({"adjoint", "ic"})->Unit(benchmark::kMillisecond);

}  // namespace
