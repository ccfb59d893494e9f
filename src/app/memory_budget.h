#pragma once
// Memory asked of the machine, estimated before a run starts: a run that cannot fit is refused at once with
// the estimate, instead of paging for minutes and ending in std::bad_alloc.
#include <cstdint>
#include <string>

#include "scene/scene.h"

namespace kf {

// The estimate counts what grows with the run: the kept states (3p positions and velocities per state),
// the trajectory written at the end, and the checkpoints. It is a lower bound: the per-step tape and the
// solver's matrices come on top.
struct RunMemory {
  std::uint64_t bytes = 0;
  std::string detail;  // "trajectory 1.2 GiB + states 3.4 GiB"
};

// `keyframe simulate`: the frames' states while simulating and the trajectory written from them.
RunMemory simulate_memory(const Scene& scene);
// `keyframe optimize` at `substeps` per frame with `checkpoint_every` (0: every state kept).
RunMemory optimize_memory(const Scene& scene, int substeps, int checkpoint_every);

// The machine's memory: MemTotal, or the cgroup's memory.max when that is lower.
std::uint64_t machine_memory();

// "4G", "512M", "1.5GiB", "100000" (bytes) -> bytes (K, M, G, T: powers of 1024); "0" -> 0 (the command's
// default). Throws InputError naming --max-memory otherwise. What simulate's and optimize's --max-memory take.
std::uint64_t parse_memory_size(const std::string& text);

// Throws InputError "FILE: needs at least 12.7 GiB of memory (...), more than the machine's 7.8 GiB; ..."
// when the estimate exceeds `limit` (0: the machine's memory).
void check_memory(const Scene& scene, const RunMemory& need, std::uint64_t limit);

// 1536 -> "1.5 KiB".
std::string format_bytes(std::uint64_t bytes);

}  // namespace kf
