// Per-frame render cost at 1280x720: OSMesa preview (4x MSAA) and Embree at 16 spp.
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>

#include "render/frame_renderer.h"

namespace kf::render {
namespace {

RunData make_run(bool flock) {
  RunData run;
  const std::string text = flock ? R"({"time": {"frames": 10}, "flock": {"agents": 200},
      "objectives": [{"type": "shape", "frame": 10, "polygon": [[-5,-5],[5,-5],[5,5],[-5,5]]}]})"
                                 : R"({"time": {"frames": 10}, "cloth": {"nx": 50, "ny": 50}, "objectives": []})";
  run.scene = parse_scene(text, "bench.json");
  Trajectory& t = run.trajectory;
  t.particles = run.scene.particles();
  for (int f = 0; f <= 10; ++f) {
    VecX x(3 * t.particles), v = VecX::Zero(3 * t.particles);
    for (int i = 0; i < t.particles; ++i) {
      if (flock) {
        const double r = 2.0 + 8.0 * ((i * 37) % 200) / 200.0, a = i * 2.4 + 0.3 * f;
        x.segment<3>(3 * i) = Vec3(r * std::cos(a), 0, r * std::sin(a));
        v.segment<3>(3 * i) = Vec3(-std::sin(a), 0, std::cos(a));
      } else {
        const double u = (i % 50) / 49.0, w = (i / 50) / 49.0;
        x.segment<3>(3 * i) = Vec3(1.5 * u - 0.75, 1.0 + 0.15 * std::sin(6 * u + 0.3 * f) * std::cos(3 * w), 1.5 * w - 0.75);
      }
    }
    t.x.push_back(x);
    t.v.push_back(v);
  }
  return run;
}

void render_frames(benchmark::State& state, bool flock, const char* backend, int spp) {
  const RunData run = make_run(flock);
  FrameRenderer renderer(run, backend, {1280, 720, spp});
  renderer.render(0);  // shader compilation and BVH creation happen once per run
  int f = 0;
  for (auto _ : state) benchmark::DoNotOptimize(renderer.render(f++ % 11));
}

void BM_OsMesa720p_Cloth50x50(benchmark::State& s) { render_frames(s, false, "osmesa", 4); }
void BM_OsMesa720p_Flock200(benchmark::State& s) { render_frames(s, true, "osmesa", 4); }
void BM_Embree720p16spp_Cloth50x50(benchmark::State& s) { render_frames(s, false, "embree", 16); }
void BM_Embree720p16spp_Flock200(benchmark::State& s) { render_frames(s, true, "embree", 16); }

BENCHMARK(BM_OsMesa720p_Cloth50x50)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_OsMesa720p_Flock200)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Embree720p16spp_Cloth50x50)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);
BENCHMARK(BM_Embree720p16spp_Flock200)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

}  // namespace
}  // namespace kf::render
