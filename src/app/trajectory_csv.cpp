#include "app/trajectory_csv.h"

#include <cstdio>
#include <ostream>
#include <string>

#include "core/atomic_file.h"
#include "core/dir_lock.h"
#include "core/error.h"
#include "core/trajectory.h"

namespace kf {
namespace fs = std::filesystem;

fs::path export_trajectory_csv(const fs::path& run_dir, int begin, int end) {
  if (!fs::is_directory(run_dir)) throw InputError(run_dir.string() + ": not a run directory");
  const DirLock lock(run_dir, DirLock::Mode::kShared);  // no optimisation replaces the run meanwhile
  const Trajectory t = load_trajectory(run_dir / "trajectory.bin");
  const int F = t.frames();
  const int last = end < 0 ? F : end;
  if (begin < 0 || begin >= F || last <= begin || last > F)
    throw InputError("frames " + std::to_string(begin) + ":" + std::to_string(end) + " out of range: " +
                     run_dir.string() + " has frames 0.." + std::to_string(F - 1) + " (A:B exports A..B-1)");
  const fs::path dir = run_dir / "export";
  ensure_directory(dir);
  const fs::path file = dir / "trajectory.csv";
  write_stream_atomic(file, [&](std::ostream& out) {
    out << "frame,seconds,particle,x,y,z,vx,vy,vz\n";
    char row[512];
    for (int f = begin; f < last; ++f)
      for (int i = 0; i < t.particles; ++i) {
        const double* x = t.x[f].data() + 3 * i;
        const double* v = t.v[f].data() + 3 * i;
        std::snprintf(row, sizeof row, "%d,%.17g,%d,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", f, f / t.fps, i, x[0],
                      x[1], x[2], v[0], v[1], v[2]);
        out << row;
      }
  });
  return file;
}

}  // namespace kf
