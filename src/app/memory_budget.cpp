#include "app/memory_budget.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <regex>

#include "core/error.h"

namespace kf {

namespace {
constexpr double kStateBytesPerParticle = 2 * 3 * sizeof(double);  // x and v, 3 doubles each

std::uint64_t states_bytes(const Scene& scene, double states) {
  return std::uint64_t(states * kStateBytesPerParticle * scene.particles());
}
}  // namespace

std::string format_bytes(std::uint64_t bytes) {
  const char* units[] = {"bytes", "KiB", "MiB", "GiB", "TiB", "PiB"};
  double v = double(bytes);
  int u = 0;
  while (v >= 1024 && u < 5) v /= 1024, ++u;
  char s[32];
  std::snprintf(s, sizeof s, u == 0 ? "%.0f %s" : "%.1f %s", v, units[u]);
  return s;
}

RunMemory simulate_memory(const Scene& scene) {
  // simulate_frames keeps the frames' states, then frames_of copies them into the trajectory.
  const std::uint64_t frames = states_bytes(scene, scene.time.frames + 1.0);
  return {2 * frames, "frame states " + format_bytes(frames) + " + trajectory " + format_bytes(frames)};
}

RunMemory optimize_memory(const Scene& scene, int substeps, int checkpoint_every) {
  const double N = double(scene.time.frames) * substeps;
  // Stored mode keeps every state; checkpointed mode every k-th, a k-state segment buffer and the states
  // the keyframes read.
  const double k = checkpoint_every > 0 ? std::min<double>(checkpoint_every, N) : 0;
  const double states = k > 0 ? std::ceil(N / k) + 1 + k + 1 + double(scene.objectives.size()) : N + 1;
  const std::uint64_t kept = states_bytes(scene, states);
  const std::uint64_t trajectory = states_bytes(scene, scene.time.frames + 1.0);
  return {kept + trajectory, "kept states " + format_bytes(kept) + " + trajectory " + format_bytes(trajectory)};
}

std::uint64_t machine_memory() {
  std::uint64_t total = 0;
  std::ifstream meminfo("/proc/meminfo");
  std::string key, unit;
  std::uint64_t value = 0;
  while (meminfo >> key >> value >> unit)
    if (key == "MemTotal:") {
      total = value * 1024;
      break;
    }
  std::ifstream cgroup("/sys/fs/cgroup/memory.max");
  std::string limit;
  if (cgroup >> limit && limit != "max") {
    try {
      total = std::min<std::uint64_t>(total ? total : UINT64_MAX, std::stoull(limit));
    } catch (...) {
    }
  }
  return total;
}

std::uint64_t parse_memory_size(const std::string& text) {
  static const std::regex re(R"((\d+(?:\.\d+)?)\s*([KMGT]?)(i?B)?)", std::regex::icase);
  std::smatch m;
  if (!std::regex_match(text, m, re))
    throw InputError("--max-memory: expected a size such as 4G, 512M or 1.5GiB, got \"" + text + "\"");
  double v = std::stod(m[1]);
  const std::string unit = m[2];
  const int shift = unit.empty() ? 0 : std::string("KMGT").find(char(std::toupper(unit[0]))) + 1;
  v *= std::pow(1024.0, shift);
  if (v == 0) return 0;  // the command's default
  if (!(v >= 1) || v > 1e18) throw InputError("--max-memory: out of range, got \"" + text + "\"");
  return std::uint64_t(v);
}

void check_memory(const Scene& scene, const RunMemory& need, std::uint64_t limit) {
  const bool machine = limit == 0;
  if (machine) limit = machine_memory();
  if (limit == 0 || need.bytes <= limit) return;
  throw InputError(scene.file.string() + ": needs at least " + format_bytes(need.bytes) + " of memory (" +
                   need.detail + "), more than " +
                   (machine ? "the machine's " + format_bytes(limit) : "--max-memory " + format_bytes(limit)) +
                   "; shorten the run, use fewer particles or set optimizer.checkpoint_every");
}

}  // namespace kf
