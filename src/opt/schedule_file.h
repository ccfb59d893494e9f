#pragma once
// schedule.bin: the step schedule a run's result was judged under (sim/system.h; on cloth the split pattern its
// last stage held: per step, the depths of its accepted substeps), beside controls.bin, so that whatever simulates
// those controls again (a resume, `gradcheck --at`) takes the steps the run took and lands where it did.
// Format (little-endian): 8-byte magic "KFSCHEDL", uint32 version (1), uint32 substeps, uint32 steps, uint64 the
// fingerprint of the controls it goes with (FNV-1a of their float64s), uint64 depths in all, then per step the
// uint32 count of its substeps, then every step's depths (uint8) in order. A step without substeps decides afresh.
#include <cstdint>
#include <filesystem>

#include "core/types.h"
#include "scene/scene.h"
#include "sim/system.h"

namespace kf {

// The fingerprint stored with a schedule: of the controls' values, bit for bit.
std::uint64_t controls_fingerprint(const VecX& z);

// Writes `schedule` (padded or cut to `steps` steps) for controls z at `substeps` atomically; removes a stale file
// when the schedule is empty (a run that held none: a flock, a cloth that checks every step).
void save_schedule(const std::filesystem::path& path, const StepSchedule& schedule, const VecX& z, int substeps,
                   int steps);

// The schedule stored at `path` for controls z at `substeps` of `scene`; empty when there is no file. Throws
// InputError naming the file when it is not a regular file, is truncated or corrupt, was made for other controls
// or another step length, or holds a pattern the scene's cloth cannot take.
StepSchedule load_schedule(const std::filesystem::path& path, const Scene& scene, const VecX& z, int substeps);

// The schedule run directory `dir` stores for its controls z (load_schedule of dir/schedule.bin). A directory
// without one, of a scene whose runs hold their schedule (an older run), gives an empty schedule and a warning,
// once, that the schedule is chosen anew.
StepSchedule run_schedule(const std::filesystem::path& dir, const Scene& scene, const VecX& z, int substeps);

}  // namespace kf
