// keyframe render RUN_DIR: render a run directory's trajectory to PNG frames.
#include <iostream>

#include "app/camera_options.h"
#include "app/cli_ranges.h"
#include "app/commands.h"
#include "core/error.h"
#include "render/backend.h"
#include "render/render_run.h"

namespace kf {

void add_render_command(CLI::App& app) {
  auto* sub = app.add_subcommand("render", "render a run directory to PNG frames (RUN_DIR/frames/frame_NNNN.png)");
  auto req = std::make_shared<render::RenderRequest>();
  auto size = std::make_shared<std::string>();
  auto frames = std::make_shared<std::string>();
  auto views = std::make_shared<std::string>();
  auto camera = std::make_shared<CameraWords>();
  std::string names;
  for (const auto& n : render::backend_names()) names += (names.empty() ? "" : "|") + n;
  auto run_dir = std::make_shared<std::string>();
  sub->add_option("RUN_DIR", *run_dir, "run directory holding scene.json and trajectory.bin (required)");
  sub->add_option("--backend", req->backend,
                  "renderer: osmesa = fast raster preview, embree = ray traced with soft shadows (" + names + ")")
      ->capture_default_str();
  sub->add_option("--size", *size, "image size WxH in pixels (default: the scene's render.width x height)");
  sub->add_option("--spp", req->spp, "samples per pixel (default: osmesa 4 (MSAA), embree render.samples)");
  sub->add_option("--frames", *frames, "frames A:B renders A..B-1 (default: all)");
  sub->add_option("--turntable", req->turntable,
                  "orbit the camera around the first frame in N views (frames/turntable_NNNN.png)");
  sub->add_option("--views", *views, "with --turntable: render views A:B (A..B-1) only, e.g. one farm task's share");
  add_camera_options(sub, *camera);
  sub->footer("Frames are written whole or not at all; a bad request writes nothing.\n"
              "Example: keyframe render out/square --backend embree --size 1280x720 --spp 16\n"
              "         keyframe render out/square --view top\n"
              "         keyframe render out/cape-a --camera \"eye=0,1.6,4 target=0,1,0 fov=35\"");
  sub->callback([=] {
    render::RenderRequest r = *req;
    r.run_dir = one_positional(*camera, *run_dir, "RUN_DIR");
    if (!size->empty()) parse_size(*size, r.width, r.height);
    if (!frames->empty()) parse_frames(*frames, r.frame_begin, r.frame_end);
    if (!views->empty()) parse_frames(*views, r.view_begin, r.view_end, "--views");
    r.camera = camera_choice(*camera);
    const int n = render::render_run(r);
    std::cout << "rendered " << n << " frame" << (n == 1 ? "" : "s") << " -> " << (r.run_dir / "frames").string()
              << "\n";
  });
}

}  // namespace kf
