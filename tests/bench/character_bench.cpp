// Character posing and body closest-point queries: the per-step cost the cape simulation pays.
#include <benchmark/benchmark.h>

#include <filesystem>

#include "sim/character/body_query.h"
#include "sim/character/character.h"

namespace {

// The bench target has no source-dir define: find the asset from this file's path (tests/bench/..).
const std::filesystem::path kAsset =
    std::filesystem::path(__FILE__).parent_path().parent_path().parent_path() / "assets/character/BCN_Epileptic.X";

// A 16 x 26 cape-sized grid of points 4 cm apart, hanging a few centimetres behind the back.
kf::VecX cape_points() {
  kf::VecX p(3 * 16 * 26);
  for (int i = 0; i < 16; ++i)
    for (int j = 0; j < 26; ++j) kf::seg(p, i * 26 + j) = kf::Vec3(-0.3 + 0.04 * i, 0.5 - 0.04 * j, -0.30);
  return p;
}

void BM_CharacterPose(benchmark::State& state) {
  kf::Character c(kAsset);
  kf::VecX x;
  double t = 0.0;
  for (auto _ : state) {
    c.pose(t, x);
    t += 1.0 / 120.0;
    benchmark::DoNotOptimize(x.data());
  }
  state.counters["vertices"] = c.vertex_count();
}
BENCHMARK(BM_CharacterPose)->Unit(benchmark::kMicrosecond);

void BM_CharacterVertexNormals(benchmark::State& state) {
  kf::Character c(kAsset);
  kf::VecX x, n;
  c.pose(1.0, x);
  for (auto _ : state) {
    c.vertex_normals(x, n);
    benchmark::DoNotOptimize(n.data());
  }
}
BENCHMARK(BM_CharacterVertexNormals)->Unit(benchmark::kMicrosecond);

// BVH refit plus normals for a new pose.
void BM_BodyQueryUpdate(benchmark::State& state) {
  kf::Character c(kAsset);
  kf::BodyQuery q(c.triangles(), c.vertex_count());
  kf::VecX x;
  c.pose(1.0, x);
  for (auto _ : state) q.update(x);
}
BENCHMARK(BM_BodyQueryUpdate)->Unit(benchmark::kMicrosecond);

// 416 queries (a 16 x 26 cape) against one pose; argument = search radius in millimetres.
void BM_BodyQueryBatch416(benchmark::State& state) {
  kf::Character c(kAsset);
  kf::BodyQuery q(c.triangles(), c.vertex_count());
  kf::VecX x;
  c.pose(1.2, x);
  q.update(x);
  const kf::VecX points = cape_points();
  const double radius = 1e-3 * static_cast<double>(state.range(0));
  std::vector<kf::BodyHit> hits;
  int found = 0;
  for (auto _ : state) {
    q.closest_batch(points, radius, hits);
    benchmark::DoNotOptimize(hits.data());
  }
  for (const auto& h : hits) found += h.found();
  state.counters["found"] = found;
}
BENCHMARK(BM_BodyQueryBatch416)->Arg(20)->Arg(100)->Arg(300)->Unit(benchmark::kMicrosecond);

// The same batch one query at a time on this thread (no TBB).
void BM_BodyQuerySerial416(benchmark::State& state) {
  kf::Character c(kAsset);
  kf::BodyQuery q(c.triangles(), c.vertex_count());
  kf::VecX x;
  c.pose(1.2, x);
  q.update(x);
  const kf::VecX points = cape_points();
  const double radius = 1e-3 * static_cast<double>(state.range(0));
  for (auto _ : state)
    for (int i = 0; i < 416; ++i) benchmark::DoNotOptimize(q.closest(kf::seg(points, i), radius));
}
BENCHMARK(BM_BodyQuerySerial416)->Arg(100)->Unit(benchmark::kMicrosecond);

// Reference: brute force over all 5,126 triangles for the same 416 points.
void BM_BodyBruteForce416(benchmark::State& state) {
  kf::Character c(kAsset);
  kf::BodyQuery q(c.triangles(), c.vertex_count());
  kf::VecX x;
  c.pose(1.2, x);
  q.update(x);
  const kf::VecX points = cape_points();
  for (auto _ : state)
    for (int i = 0; i < 416; ++i) benchmark::DoNotOptimize(q.surface().closest_brute_force(kf::seg(points, i), 0.1));
}
BENCHMARK(BM_BodyBruteForce416)->Unit(benchmark::kMillisecond);

// One cloth step's worth of body work: pose, refit, 416 queries.
void BM_CapeStepBodyWork(benchmark::State& state) {
  kf::Character c(kAsset);
  kf::BodyQuery q(c.triangles(), c.vertex_count());
  kf::VecX x;
  const kf::VecX points = cape_points();
  std::vector<kf::BodyHit> hits;
  double t = 0.0;
  for (auto _ : state) {
    c.pose(t, x);
    q.update(x);
    q.closest_batch(points, 0.1, hits);
    t += 1.0 / 120.0;
  }
}
BENCHMARK(BM_CapeStepBodyWork)->Unit(benchmark::kMicrosecond);

}  // namespace
