// keyframe run SCENE: optimise, then render the result.
#include <iostream>

#include "app/commands.h"
#include "app/optimize_job.h"
#include "render/backend.h"
#include "render/render_run.h"

namespace kf {

void add_run_command(CLI::App& app) {
  auto* sub = app.add_subcommand("run", "optimize the scene, then render it to <run dir>/frames/frame_%04d.png");
  auto scene = std::make_shared<std::string>();
  auto opts = std::make_shared<OptimizeOptions>();
  auto backend = std::make_shared<std::string>("osmesa");
  sub->add_option("SCENE", *scene, "scene file (JSON)")->required();
  add_optimize_options(sub, *opts);
  sub->add_option("--backend", *backend, "renderer: osmesa (fast preview) or embree (ray traced)")
      ->check(CLI::IsMember(render::backend_names()));
  sub->callback([=] {
    const auto outcome = optimize_job(*scene, *opts);
    exit_if_interrupted(outcome);
    const auto& dir = outcome.dir;
    render::RenderRequest req;
    req.run_dir = dir;
    req.backend = *backend;
    const int n = render::render_run(req);
    std::cout << "rendered " << n << " frames into " << (dir / "frames").string() << "\n";
  });
}

}  // namespace kf
