// Scene loading cost (a baseline; the simulation benchmarks sit beside this file).
#include <benchmark/benchmark.h>

#include "scene/params.h"

static void BM_BlockRead(benchmark::State& state) {
  const auto j = kf::Json::parse(R"({"a": 2, "b": [1, 2, 3]})");
  for (auto _ : state) {
    kf::Block b(j, "s.json");
    benchmark::DoNotOptimize(b.integer("a", 0, 0, 10));
    benchmark::DoNotOptimize(b.vec3("b"));
    b.finish();
  }
}
BENCHMARK(BM_BlockRead);
