#pragma once
// keyframe export --format csv: a run's trajectory.bin as one table a spreadsheet or a script reads.
#include <filesystem>

namespace kf {

// Writes RUN_DIR/export/trajectory.csv (atomically) with the header
// frame,seconds,particle,x,y,z,vx,vy,vz and one row per particle per frame of frames [begin, end)
// (end -1: to the last), values at full double precision (metres, m/s, world frame, Y up).
// Throws InputError naming the run for a missing or bad trajectory or a frame range outside it.
std::filesystem::path export_trajectory_csv(const std::filesystem::path& run_dir, int begin, int end);

}  // namespace kf
