// Memory sweep: peak resident memory of one cloth gradient against steps, with and without checkpoints.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>

#include "bench/bench_point.h"
#include "bench/bench_sweeps.h"
#include "report/plot.h"
#include "core/error.h"
#include "opt/problem.h"
#include "sim/make_system.h"

namespace kf {

namespace {

// Peak resident set size of this process so far, kB (Linux /proc/self/status VmHWM).
long peak_rss_kb() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::stol(line.substr(6));
  return -1;
}

constexpr int kSubsteps = 40;

}  // namespace

void memory_point(int steps, int every, int resolution) {
  const int frames = std::max(1, steps / kSubsteps);
  const std::string text = R"({
    "time": {"fps": 30, "substeps": )" + std::to_string(kSubsteps) + R"(, "frames": )" + std::to_string(frames) + R"(},
    "cloth": {"nx": )" + std::to_string(resolution) + R"(, "ny": )" + std::to_string(resolution) + R"(, "pins": "top_corners"},
    "objectives": [{"type": "center_of_mass", "frame": )" + std::to_string(frames) + R"(, "target": [0.5, 0.3, 0.3]}],
    "controls": {"kind": "per_frame", "alpha": 0.001},
    "optimizer": {"checkpoint_every": )" + std::to_string(every) + R"(}
  })";
  const Scene scene = parse_scene(text, "bench_memory.json");
  auto sys = make_system(scene);
  Problem problem(scene, scene.time, *sys);
  VecX g(problem.size());
  const long base = peak_rss_kb();
  const auto t0 = std::chrono::steady_clock::now();
  problem.evaluate(problem.initial_guess(), &g);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const nlohmann::json j = {{"steps", scene.time.steps()},
                            {"checkpoint_every", every},
                            {"peak_kb", peak_rss_kb()},
                            {"base_kb", base},
                            {"state_bytes", problem.rollout().stored_bytes()},
                            {"gradient_s", secs},
                            {"grad_norm", g.norm()}};
  std::cout << j.dump() << std::endl;
}

nlohmann::json bench_memory(const MemorySweepOptions& o, const std::filesystem::path& out,
                            const std::filesystem::path& self) {
  CsvTable t({"steps", "peak_kb_stored", "peak_kb_checkpointed", "base_kb", "state_kb_stored",
              "state_kb_checkpointed", "gradient_s_stored", "gradient_s_checkpointed", "time_ratio",
              "grad_norm_stored", "grad_norm_checkpointed"});
  nlohmann::json points = nlohmann::json::array();
  for (int steps : o.steps) {
    nlohmann::json pair[2];
    for (int k = 0; k < 2; ++k) {
      const int every = k ? o.checkpoint_every : 0;
      std::cerr << "bench memory: " << steps << " steps, checkpoint_every " << every << std::endl;
      const std::string cmd = "'" + self.string() + "' --threads 1 bench --memory-point " + std::to_string(steps) +
                              " --memory-every " + std::to_string(every) + " --memory-resolution " +
                              std::to_string(o.resolution);
      FILE* child = popen(cmd.c_str(), "r");
      if (!child) throw OutputError("bench: cannot start " + self.string());
      std::string text;
      char buf[512];
      while (std::fgets(buf, sizeof buf, child)) text += buf;
      if (pclose(child) != 0) throw OutputError("bench: memory point failed: " + cmd);
      pair[k] = nlohmann::json::parse(text);
      points.push_back(pair[k]);
    }
    const double ts = pair[0]["gradient_s"], tc = pair[1]["gradient_s"];
    t.add({std::to_string(steps), std::to_string(pair[0]["peak_kb"].get<long>()),
           std::to_string(pair[1]["peak_kb"].get<long>()), std::to_string(pair[0]["base_kb"].get<long>()),
           fmt(pair[0]["state_bytes"].get<double>() / 1024), fmt(pair[1]["state_bytes"].get<double>() / 1024),
           fmt(ts), fmt(tc), fmt(tc / ts), fmt(pair[0]["grad_norm"]), fmt(pair[1]["grad_norm"])});
  }
  const auto csv = out / "memory_steps.csv";
  t.write(csv);
  plot_csv(csv, out / "memory_steps.png",
           "cloth gradient: peak resident kB against steps (checkpoint every " + std::to_string(o.checkpoint_every) + ")",
           t.col("steps"), {t.col("peak_kb_stored"), t.col("peak_kb_checkpointed")}, false);
  std::cout << "memory_steps.csv\n" << t.excerpt() << std::endl;
  return {{"table", t.excerpt()}, {"points", points}};
}

}  // namespace kf
