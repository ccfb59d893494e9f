// One flock step and one adjoint step at 200, 1,000 and 10,000 agents (default forces, ~1 m apart), and at
// 10,000 agents packed 8 times as densely (~50 neighbours each, as a crowd bunches when it is steered), and
// 100,000 packed 16 times (~300 each, as the crowd sweep's 100,000 agents pack into its shapes' edges), also
// with the sweep's implicit damping (whose adjoint adds the summed weights' pair term).
#include <benchmark/benchmark.h>

#include <cmath>

#include "sim/flock/flock_system.h"

namespace {

struct FlockFixture {
  // density: agents per unit area over the default (~1 per m^2). A spawn disc holds agents no closer than
  // the avoidance radius allows, so a denser crowd is the default one drawn together about its centre.
  FlockFixture(int agents, double density, bool implicit_damping) {
    kf::FlockSpec spec;
    spec.agents = agents;
    spec.implicit_damping = implicit_damping;
    spec.spawn.radius = std::sqrt(agents / M_PI) * 1.05;
    spec.spawn.velocity = kf::Vec3(1, 0, 0);
    sys = std::make_unique<kf::FlockSystem>(spec, 1.0 / 30, 100, 1);
    sys->initial_state(x, v);
    x /= std::sqrt(density);
    u = kf::VecX::Zero(x.size());
    xhat1 = kf::VecX::Constant(x.size(), 0.1);
    vhat1 = kf::VecX::Constant(x.size(), -0.2);
    sys->step(0, x, v, u, x1, v1);  // first call sizes every buffer
  }
  std::unique_ptr<kf::FlockSystem> sys;
  kf::VecX x, v, u, x1, v1, xhat1, vhat1, xhat, vhat, uhat;
};

void BM_FlockStep(benchmark::State& state) {
  FlockFixture f(int(state.range(0)), double(state.range(1)), state.range(2) != 0);
  for (auto _ : state) {
    f.sys->step(1, f.x, f.v, f.u, f.x1, f.v1);
    benchmark::DoNotOptimize(f.x1.data());
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

void BM_FlockStepAdjoint(benchmark::State& state) {
  FlockFixture f(int(state.range(0)), double(state.range(1)), state.range(2) != 0);
  f.sys->step_adjoint(1, f.x, f.v, f.u, f.xhat1, f.vhat1, f.xhat, f.vhat, f.uhat);
  for (auto _ : state) {
    f.sys->step_adjoint(1, f.x, f.v, f.u, f.xhat1, f.vhat1, f.xhat, f.vhat, f.uhat);
    benchmark::DoNotOptimize(f.xhat.data());
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

// Agents, density (over ~1 per m^2) and implicit damping (0 or 1) of each case.
void flock_cases(benchmark::internal::Benchmark* b) {
  const int cases[][3] = {{200, 1, 0}, {1000, 1, 0}, {10000, 1, 0}, {10000, 8, 0}, {100000, 16, 0}, {100000, 16, 1}};
  for (const auto& [agents, density, implicit] : cases) b->Args({agents, density, implicit});
}

}  // namespace

BENCHMARK(BM_FlockStep)->Apply(flock_cases)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FlockStepAdjoint)->Apply(flock_cases)->Unit(benchmark::kMicrosecond);
