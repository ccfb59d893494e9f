// keyframe figure RUN_DIR...: compose a labelled figure sheet from run directories.
#include <iostream>
#include <sstream>

#include "app/camera_options.h"
#include "app/commands.h"
#include "core/error.h"
#include "render/figure/make_figure.h"

namespace kf {

namespace {

// --frames: comma-separated frame numbers, "key" (each run's last keyframe) or "last". Throws InputError.
std::vector<int> parse_figure_frames(const std::string& text) {
  std::vector<int> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (item == "key" || item == "last") {
      out.push_back(item == "key" ? render::kLastKeyframe : render::kLastFrame);
      continue;
    }
    try {
      size_t used = 0;
      const int f = std::stoi(item, &used);
      if (used != item.size() || f < 0) throw std::invalid_argument(item);
      out.push_back(f);
    } catch (const std::exception&) {
      throw InputError("--frames: expected comma-separated frame numbers, got \"" + text + "\"");
    }
  }
  return out;
}

}  // namespace

void add_figure_command(CLI::App& app) {
  auto* sub = app.add_subcommand("figure", "compose a typeset figure sheet (out/figures/NAME.png and NAME.pdf) from run directories");
  auto req = std::make_shared<render::FigureRequest>();
  auto frames = std::make_shared<std::string>();
  auto size = std::make_shared<std::string>();
  auto camera = std::make_shared<CameraWords>();
  sub->add_option("RUN_DIR", req->run_dirs, "run directories, one row each (at least one)");
  sub->add_option("--frames", *frames,
                  "comma-separated frames, e.g. 0,30,60; 'key' = each run's last keyframe, 'last' = its last "
                  "frame (default: 0, keyframes, last)");
  sub->add_flag("--columns", req->columns, "runs side by side, frames going down (paper figures 1 and 6)");
  sub->add_option("--name", req->name, "file name without .png/.pdf (default: the first run's scene name)");
  sub->add_option("--title", req->title, "set above the sheet (default: the first run's scene name)");
  sub->add_option("--caption", req->caption, "set under the sheet, e.g. the paper's caption");
  sub->add_option("--labels", req->labels, "comma-separated names of the runs, one per RUN_DIR in order (default: "
                                           "each run's scene name)")
      ->delimiter(',');
  sub->add_option("--out-dir", req->out_dir, "where the sheet goes")->capture_default_str();
  sub->add_option("--backend", req->backend, "osmesa | embree")->capture_default_str();
  sub->add_option("--size", *size, "tile size WxH in pixels (default 400x300)");
  sub->add_option("--spp", req->spp, "samples per pixel (default: back end default)");
  sub->add_flag("--overlay", req->overlay, "one tile per run: a flock's path (its agents at these frames, trails of a few agents, the centre of mass), other runs' frames superimposed");
  add_camera_options(sub, *camera);
  sub->footer("Paper layouts, after keyframe run scenes/NAME.json for each run named (scripts/readme-figures makes\n"
              "them all with Embree):\n"
              "  fig. 1  keyframe figure out/square out/cross out/arch --columns --frames key\n"
              "  fig. 2  keyframe figure out/race                      (a strip over time)\n"
              "  fig. 3  keyframe figure out/path --overlay --frames 0,60,120\n"
              "  fig. 4  keyframe figure out/shapes\n"
              "  fig. 5  keyframe figure out/ring-toss --frames 0,5,9,14,21,28\n"
              "  fig. 6  keyframe figure out/cape-a out/cape-blend out/cape-b --columns --frames 0,15,last");
  sub->callback([=] {
    render::FigureRequest r = *req;
    for (const std::string& dir : positionals_after_camera(*camera)) r.run_dirs.push_back(dir);
    if (r.run_dirs.empty()) throw CLI::RequiredError("RUN_DIR");
    r.camera = camera_choice(*camera);
    if (!frames->empty()) r.frames = parse_figure_frames(*frames);
    if (!size->empty()) {
      char x = 0;
      std::stringstream ss(*size);
      if (!(ss >> r.width >> x >> r.height) || (x != 'x' && x != 'X') || !ss.eof())
        throw InputError("--size: expected WxH such as 400x300, got \"" + *size + "\"");
    }
    const auto path = render::make_figure(r);
    std::cout << "figure -> " << path.string() << "\n";
  });
}

}  // namespace kf
