#include "render/render_run.h"

#include <cmath>
#include <cstdio>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/progress.h"
#include "render/frame_renderer.h"

namespace kf::render {

namespace {
constexpr int kMaxSize = 8192;
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
  FrameRenderer renderer(run, request.backend, {request.width, request.height, request.spp});
  const auto dir = request.run_dir / "frames";
  ensure_directory(dir);
  const bool turntable = request.turntable > 0;
  // A turntable may be rendered a range of views at a time (farm tasks); the orbit angle uses all views.
  const int first = turntable ? request.view_begin : 0;
  const int last = turntable ? (request.view_end < 0 ? request.turntable : request.view_end) : end - begin;
  const int count = last - first;
  Progress progress("render " + request.backend, count);
  char name[64];
  for (int k = first; k < last; ++k) {
    const Image img =
        turntable ? renderer.render(begin, 2.0 * M_PI * k / request.turntable) : renderer.render(begin + k);
    std::snprintf(name, sizeof name, turntable ? "turntable_%04d.png" : "frame_%04d.png", turntable ? k : begin + k);
    write_png(dir / name, img);
    progress.update(k - first + 1, name);
  }
  progress.finish();
  return count;
}

}  // namespace kf::render
