#include "render/render_run.h"

#include <cmath>
#include <cstdio>
#include <optional>
#include <vector>

#include "core/atomic_file.h"
#include "core/dir_lock.h"
#include "core/error.h"
#include "core/staged_dir.h"
#include "core/progress.h"
#include "render/frame_renderer.h"

namespace kf::render {

namespace fs = std::filesystem;

namespace {
constexpr int kMaxSize = 8192;

// Removes frame_NNNN.png with NNNN >= frames: what a longer earlier run left.
void remove_frames_past(const fs::path& dir, int frames) {
  std::error_code ec;
  std::vector<fs::path> stale;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    int k = -1;
    char tail[8] = {};
    if (std::sscanf(name.c_str(), "frame_%d.%7s", &k, tail) == 2 && std::string(tail) == "png" && k >= frames)
      stale.push_back(it->path());
  }
  for (const auto& p : stale) fs::remove(p, ec);
}
}  // namespace

void check_request(const RenderRequest& r) {
  bool known = false;
  for (const auto& n : backend_names()) known = known || n == r.backend;
  if (!known) make_backend(r.backend);  // throws the message listing the choices
  if (r.width < 0 || r.height < 0 || r.width > kMaxSize || r.height > kMaxSize || (r.width == 0) != (r.height == 0) ||
      (r.width > 0 && (r.width < 16 || r.height < 16)))
    throw InputError("image size " + std::to_string(r.width) + "x" + std::to_string(r.height) +
                     " out of range (each side 16.." + std::to_string(kMaxSize) + " pixels)");
  if (r.spp < 0 || r.spp > 65536)
    throw InputError("samples per pixel " + std::to_string(r.spp) + " out of range (1..65536)");
  if (r.turntable < 0 || r.turntable > 100000)
    throw InputError("turntable frame count " + std::to_string(r.turntable) + " out of range (1..100000)");
  const int views_end = r.view_end < 0 ? r.turntable : r.view_end;
  if ((r.view_begin != 0 || r.view_end >= 0) && (r.view_begin < 0 || views_end <= r.view_begin || views_end > r.turntable))
    throw InputError("views " + std::to_string(r.view_begin) + ":" + std::to_string(r.view_end) +
                     " out of range: the turntable has views 0.." + std::to_string(r.turntable - 1) +
                     " (A:B renders A..B-1; needs --turntable)");
}

int render_run(const RenderRequest& request) {
  check_request(request);
  const RunData run = load_run(request.run_dir);
  const int F = run.trajectory.frames();
  const int begin = request.frame_begin, end = request.frame_end < 0 ? F : request.frame_end;
  if (begin < 0 || begin >= F || end <= begin || end > F)
    throw InputError("frames " + std::to_string(begin) + ":" + std::to_string(request.frame_end) +
                     " out of range: " + request.run_dir.string() + " has frames 0.." + std::to_string(F - 1) +
                     " (A:B renders A..B-1)");
  FrameRenderer renderer(run, request.backend, {request.width, request.height, request.spp}, request.camera);
  const bool turntable = request.turntable > 0;
  // A whole render goes into a fresh folder swapped in at the end, so no frame of an earlier, longer run
  // survives; a part (--frames A:B, --views: farm tasks rendering side by side) adds its files to frames/.
  const bool whole = !turntable && begin == 0 && end == F;
  const fs::path final_dir = request.run_dir / "frames";
  DirLock lock(request.run_dir, whole ? DirLock::Mode::kExclusive : DirLock::Mode::kShared);
  std::optional<StagedDir> staged;
  if (whole) staged.emplace(final_dir);
  else ensure_directory(final_dir);
  const fs::path dir = whole ? staged->path() : final_dir;
  // A turntable may be rendered a range of views at a time (farm tasks); the orbit angle uses all views.
  const int first = turntable ? request.view_begin : 0;
  const int last = turntable ? (request.view_end < 0 ? request.turntable : request.view_end) : end - begin;
  const int count = last - first;
  Progress progress("render " + request.backend, count);
  char name[64];
  try {
    for (int k = first; k < last; ++k) {
      const Image img =
          turntable ? renderer.render(begin, 2.0 * M_PI * k / request.turntable) : renderer.render(begin + k);
      std::snprintf(name, sizeof name, turntable ? "turntable_%04d.png" : "frame_%04d.png", turntable ? k : begin + k);
      write_png(dir / name, img);
      progress.update(k - first + 1, name);
    }
    if (whole) {
      // Turntable views of an earlier render stay: they are not frames of the trajectory.
      staged->copy_from_target([](const std::string& n) { return n.rfind("turntable_", 0) == 0; });
      staged->commit();
    } else if (!turntable) {
      remove_frames_past(final_dir, F);
    }
  } catch (const OutputError& e) {
    throw OutputError(staged ? staged->public_message(e.what()) : std::string(e.what()));
  }
  progress.finish();
  return count;
}

}  // namespace kf::render
