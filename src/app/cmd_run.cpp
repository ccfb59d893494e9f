// keyframe run SCENE: optimise, then render the result.
#include <iostream>

#include "app/commands.h"
#include "app/camera_options.h"
#include "app/cli_ranges.h"
#include "app/optimize_job.h"
#include "render/backend.h"
#include "render/render_run.h"

namespace kf {

void add_run_command(CLI::App& app) {
  auto* sub = app.add_subcommand("run", "optimize the scene, then render it to <run dir>/frames/frame_%04d.png");
  auto scene = std::make_shared<std::string>();
  auto opts = std::make_shared<OptimizeOptions>();
  auto req = std::make_shared<render::RenderRequest>();
  auto size = std::make_shared<std::string>();
  auto camera = std::make_shared<CameraWords>();
  sub->add_option("SCENE", *scene, "scene file (JSON) (required)");
  add_optimize_options(sub, *opts);
  sub->add_option("--backend", req->backend, "renderer: osmesa (fast preview) or embree (ray traced)")
      ->check(CLI::IsMember(render::backend_names()))
      ->capture_default_str();
  sub->add_option("--size", *size, "image size WxH in pixels (default: the scene's render.width x height)");
  sub->add_option("--spp", req->spp, "samples per pixel (default: osmesa 4 (MSAA), embree render.samples)");
  add_camera_options(sub, *camera);
  sub->footer("Example: keyframe run scenes/square.json --backend embree --size 1280x720 --spp 16");
  sub->callback([=] {
    render::RenderRequest r = *req;
    const std::string scene_file = one_positional(*camera, *scene, "SCENE");
    if (!size->empty()) parse_size(*size, r.width, r.height);  // a bad size or camera fails before the optimisation
    r.camera = camera_choice(*camera);
    const auto outcome = optimize_job(scene_file, *opts);
    exit_if_interrupted(outcome);
    const auto& dir = outcome.dir;
    r.run_dir = dir;
    const int n = render::render_run(r);
    std::cout << "rendered " << n << " frames into " << (dir / "frames").string() << "\n";
    exit_if_failed(outcome);  // rendered all the same: the frames show what went wrong
  });
}

}  // namespace kf
