// What reading an untrusted mesh in a child process costs (core/mesh_import.h): the character files' import
// through assimp in this process against the same import in a forked child that sends the scene back
// through a pipe, with the steps and checks Character and `inspect` use. Arg 0: the body of the cape scenes
// (assets/character/BCN_Epileptic.X), 1: Debian's Testwuson.X; arg 1: isolated (1) or in process (0).
// tests/results/bench/mesh_import.csv: keyframe_bench --benchmark_filter=MeshImport --benchmark_repetitions=5
//   --benchmark_report_aggregates_only=true --benchmark_out_format=csv --benchmark_out=FILE
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <benchmark/benchmark.h>

#include <filesystem>

#include "core/mesh_import.h"

namespace {

const std::filesystem::path kFiles[] = {
    std::filesystem::path(__FILE__).parent_path().parent_path().parent_path() / "assets/character/BCN_Epileptic.X",
    "/usr/share/assimp/models/X/Testwuson.X"};

void BM_MeshImport(benchmark::State& state) {
  kf::MeshImportOptions options{aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_LimitBoneWeights, 4};
  options.isolated = state.range(1) != 0;
  unsigned vertices = 0;
  for (auto _ : state) {
    const auto scene = kf::import_mesh_file(kFiles[state.range(0)], options);
    vertices = 0;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) vertices += scene->mMeshes[m]->mNumVertices;
    benchmark::DoNotOptimize(vertices);
  }
  state.counters["vertices"] = vertices;
}
BENCHMARK(BM_MeshImport)->ArgsProduct({{0, 1}, {0, 1}})->ArgNames({"file", "isolated"})->Unit(benchmark::kMillisecond);

}  // namespace
